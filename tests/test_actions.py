"""The canonical action vocabulary (core/data/actions.py) and the known-actions count of a dataset."""
import json

import pytest

from shapemove.core.data.actions import ACTIONS, action, clip_actions, find_actions, known_actions, specific
from shapemove.core.errors import ShapeMoveError


def test_vocabulary():
    assert 55 <= len(ACTIONS) <= 65
    for a in ACTIONS.values():
        assert a.phrases and a.patterns and a.group
        for phrase in a.phrases:  # every phrase the captions write is recognised as its own action
            assert find_actions(phrase)[0] == a.name, (a.name, phrase)
    assert action("cartwheel").name == "cartwheel"
    with pytest.raises(ShapeMoveError, match="unknown action"):
        action("moonwalk")


@pytest.mark.parametrize("text, expected", [
    ("jumping jacks, side twists, squats, jog", ["jumping jacks", "side twist", "squat", "jog"]),
    ("A person walks backward", ["walk backward"]),
    ("WalkDigital8", ["walk in a figure eight", "walk"]),
    ("A human jumps while turning to its left hand side", ["spin jump"]),
    ("soccer - kick ball", ["kick ball"]),
    ("someone waves goodbye", ["wave goodbye"]),
    ("A person is walking forward with swinging arms", ["walk"]),
    ("turns around 180 degrees", ["turn"]),
    ("The person does a 360 clockwise jump", ["spin jump"]),
    ("a purple teapot", []),
    # everyday words (actions._EVERYDAY), a longer match over a shorter one it overlaps
    ("a tourist ambles through the park", ["walk"]),
    ("the thief tiptoes past the guard", ["sneak"]),
    ("a baby creeps along on all fours", ["crawl"]),
    ("she hurls a stone into the lake", ["throw"]),
    ("the old man reclines on the grass", ["lie down"]),
    ("a woman takes a seat", ["sit"]),
    ("the class does star jumps", ["jumping jacks"]),
    ("a knight swings a longsword", ["slash"]),
    ("a pony trots around the field", ["jog"]),
    ("a guard paces ahead", ["walk"]),
    ("circling the yard on foot", ["walk in a circle", "walk"]),
    ("a boy throws a stick for the dog", ["throw"]),
    ("a boxer throws a left hook", ["punch"]),
    ("she throws two quick jabs", ["punch"]),
    ("a fan with one fist thrust up in the air", ["raise hand"]),
    ("a person does sit-ups", []),                    # no sitting down
    ("a person does sit ups", []),
    ("a child skips happily", ["hop"]),
    ("she skips rope", ["jump"]),                     # jumps over a rope, not a skip along
    ("a boy bounces up and down on the spot", ["hop"]),   # small hops on both feet
    ("she keeps bouncing in place", ["hop"]),
    ("a ball bounces off the wall", []),
    ("a drunk man staggers", ["walk"]),
    ("a tired man drags his feet", ["walk"]),
    ("a man crouches and looks around", ["squat"]),
    ("the character creeps forward, crouched low", ["sneak"]),   # a posture of the sneak, not a squat
    ("he crouches over the table", []),               # leaning over something, not a squat
    ("a woman touches her toes", ["bend over"]),
    ("the man walks a loop around the yard", ["walk in a circle"]),
    ("a woman walks around in a big loop", ["walk in a circle", "walk"]),
    ("a child runs in a big circle", ["run", "walk in a circle"]),
    ("a man swings his arms in circles", ["arm circles"]),          # the arms' circles, no course
    ("she moves both arms around in small circles", ["arm circles"]),
    ("a man walks in circles", ["walk in a circle", "walk"]),
    ("someone lifts a heavy box", ["pick up"]),
    ("a man puts a box down on the floor", ["put down"]),   # the thing put down between the verb and "down"
    ("she picks the heavy box up", ["pick up"]),
    ("running flat out, she lifts one hand high", ["run", "raise hand"]),
    ("she paces the room", []),                       # a course (back and forth), not an action
    ("a dancer circling his arms", ["arm circles"]),   # no circle walk (vocabulary.ARM_CIRCLES); a dancer does it
    ("a woman circles her arms backwards", ["arm circles"]),
    # a person named by what they do names it only when nothing else is named
    ("a dancer performs on stage", ["dance"]),
    ("the dancer bows to the crowd", ["bow"]),
    ("a climber waves from the top", ["wave"]),
    ("a man in sneakers walks", ["walk"]), ("a creepy figure waves", ["wave"]),
    # past tenses
    ("she waved", ["wave"]), ("he threw the ball", ["throw"]), ("she stood up", ["get up"]),
    ("he got up", ["get up"]), ("the soldier marched", ["march"]), ("they danced", ["dance"]),
    ("she stretched", ["stretch"]), ("he spun around", ["spin"]),
    # lying somewhere is lying down; lying about something is not
    ("a woman lies on her back", ["lie down"]), ("he lies flat on the floor", ["lie down"]),
    ("the man lies about his age", []),
    # a twisted ankle is no side twist; favouring a leg is a limp
    ("favoring one leg after twisting an ankle", ["limp"]), ("she twists her upper body", ["side twist"]),
    ("favouring his left leg, he walks", ["limp", "walk"]),
    # backing up, shuffling sideways, stretching up, side-stepping
    ("he backs up slowly", ["walk backward"]), ("he stands back up", ["get up"]),
    ("shuffling sideways, he waves", ["sidestep", "wave"]), ("a man shuffles the cards", []),
    ("the kid stretches up on tiptoes", ["reach up"]), ("she walks on tiptoes", ["sneak", "walk"]),
    ("the goalkeeper side-steps along the line", ["sidestep"]),
    # everyday words: a walk taken in steps, struts and toddles; a dance busted; a put-down placed
    ("she takes a few steps forward", ["walk"]), ("a child toddles forward", ["walk"]),
    ("a toddler waves her right hand", ["wave"]), ("he struts toward the camera", ["walk"]),
    ("an old man shuffles forward slowly", ["walk"]), ("she takes two steps to the side", ["sidestep"]),
    ("someone is stepping backwards carefully", ["walk backward"]), ("a man shuffles to his left", ["sidestep"]),
    ("the robot busts a move", ["dance"]), ("a teenager doing a hip hop routine", ["dance"]),
    ("someone places a bag on the ground", ["put down"]), ("she lowers herself onto the floor", ["sit"]),
    ("someone grabbing a box from the ground", ["pick up"]), ("stoop and lift a box off the floor", ["pick up"]),
    ("the old man stoops over", ["bend over"]), ("a person does a back somersault", ["backflip"]),
    ("someone climbing back to their feet after a fall", ["get up"]), ("the soldier goes prone", ["lie down"]),
    ("jump and do a full turn before landing", ["spin jump"]), ("a pitcher throws a baseball", ["throw"]),
    ("the child punts a ball across the yard", ["kick ball"]), ("a player kicks a football", ["kick ball"]),
    ("the fighter hits with a right hook", ["punch"]), ("someone slicing with a katana", ["slash"]),
    ("a man gestures for someone to come over", ["beckon"]), ("a waiter shows guests the way", ["guide"]),
    ("the kid dangles from the monkey bars", ["hang"]), ("a model posing for a photo", ["pose"]),
    ("someone scrubbing their face", ["wash"]), ("a person walking with a hurt right leg", ["limp", "walk"]),
    ("someone walking an 8 shape on the floor", ["walk in a figure eight", "walk"]),
    ("a student puts up their hand", ["raise hand"]), ("standing crunches, alternating sides", ["elbow to knee"]),
    ("a man rushes to catch a bus", ["run"]), ("she runs at full speed", ["sprint"]),
    ("he rises from lying down", ["get up"]), ("she puts the box on the floor", ["put down"]),
    ("someone greets a friend", ["wave"]), ("a butler bends at the waist to greet a guest", ["bow"]),
    ("a girl moves to the beat", ["dance"]),
    # a step to one side is a sidestep, a step back a walk backward; back and forth is neither
    ("someone steps to the right", ["sidestep"]), ("she takes a step to her left", ["sidestep"]),
    ("he slides over to the left", ["sidestep"]), ("a woman steps back", ["walk backward"]),
    ("a man steps back and waves", ["walk backward", "wave"]), ("she steps back and forth", []),
    ("he steps backward and forward", []), ("a man steps forward", ["walk"]),
    # jumping over something goes forward; over and over is no obstacle
    ("a woman jumps over a puddle", ["jump forward"]), ("the dog leaps over the fence", ["jump forward"]),
    ("a boy jumps over and over", ["jump"]),
    # a thing thrown that was named before, a throw by its manner; punches, throwing up and oneself are not
    ("a man picks up a ball and throws it", ["pick up", "throw"]), ("she throws overhand", ["throw"]),
    ("she throws up", []), ("he throws himself on the floor", []),
    # hurrying somewhere is a walk (its pace: fast), unless a faster gait is named; ducking down is a crouch
    ("a man hurries to the bus", ["walk"]), ("someone hurrying forward at a run", ["run"]),
    ("he ducks down behind the wall", ["squat"]), ("a woman feeds the ducks", []),
    # a hand shot up is raised, not a basketball shot; an arm lifted, a hand waggled; a ball cleared or nudged
    ("a kid shoots her left hand up", ["raise hand"]), ("a player shoots a three-pointer", ["shoot"]),
    ("a volunteer lifts the right arm", ["raise hand"]), ("he waggles his right hand", ["wave"]),
    ("a goalkeeper clears the ball", ["kick ball"]), ("she nudges a ball with her foot", ["kick ball"]),
    # arms rolled or spun in loops circle, the body does not roll or spin; "in turn" is no turn
    ("loosen up by rolling your arms in big loops", ["arm circles"]), ("the swimmer spins both arms around", ["arm circles"]),
    ("she rolls across the floor", ["roll"]), ("bring each elbow down to the opposite knee in turn", ["elbow to knee"]),
    ("she brings her right elbow to her left knee", ["elbow to knee"]), ("they take turns", []),
    ("she springs straight up", ["jump"]), ("the boy bounces up off the ground", ["jump"]),
    ("he bounces the ball", ["dribble"]), ("a girl holds herself steady on one foot", ["balance"]),
    ("he curls his finger to call her over", ["beckon"]), ("a man folds at the waist", ["bend over"]),
    ("a woman scrambles up a steep slope", ["climb"]), ("she directs the visitors", ["guide"]),
    ("he gestures toward the door", ["guide"]), ("the attendant points out the exits", ["guide"]),
    ("a kid boots the football", ["kick ball"]), ("a man rotates his upper body", ["side twist"]),
    ("she does a spin jump", ["spin jump"]), ("he spins and jumps", ["spin", "jump"]),
    # CMU's descriptions keep their labels: sitting with the legs dangling is no hang, a dancer's lean no bend
    ("playground - climb, sit, dangle legs, descend", ["climb", "sit"]),
    ("dance - lean forward, bring back leg forward, arching arms", ["dance"]),
])
def test_find_actions(text, expected):
    assert find_actions(text) == expected


def test_specific_drops_generic():
    assert specific(["walk", "limp"]) == ["limp"] and specific(["walk", "wave"]) == ["walk", "wave"]


def test_clip_actions_per_source():
    assert clip_actions("bandai", {"content": "walk-turn-left", "style": "happy"}, []) == ["walk", "turn"]
    assert clip_actions("hdm05", {"class": "kickLFront1Reps"}, []) == ["kick"]
    assert clip_actions("hdm05", {"class": "jogLeftCircle4StepsRstart"}, []) == ["jog", "walk in a circle"]
    assert clip_actions("deepmimic", {"motion": "long_walk2_mirror"}, []) == ["walk"]
    assert clip_actions("deepmimic", {"motion": "getup_facedown"}, []) == ["get up"]
    assert clip_actions("cmu", {"description": "dance - small jetes, pirouette"}, [])[:2] == ["dance", "ballet"]
    assert clip_actions("user", {}, ["Someone does a cartwheel."]) == ["cartwheel"]


def test_known_actions_counts_a_built_dataset(tmp_path):
    (tmp_path / "meta").mkdir()
    metas = [("a", "train", ["walk"]), ("b", "train", ["walk", "wave"]), ("c", "test", ["cartwheel"]),
             ("d", "train", ["wave", "wave"])]
    for cid, split, acts in metas:
        (tmp_path / "meta" / f"{cid}.json").write_text(json.dumps({"id": cid, "split": split,
                                                                   "labels": {"actions": acts}}))
    assert known_actions(tmp_path) == [("walk", 2), ("wave", 2), ("cartwheel", 1)]
    assert known_actions(tmp_path, split="train") == [("walk", 2), ("wave", 2)]
    (tmp_path / "meta.jsonl").write_text("".join(json.dumps({"split": "train", "labels": {"actions": ["kick"]}}) + "\n"
                                                 for _ in range(3)))
    assert known_actions(tmp_path) == [("kick", 3)]                       # meta.jsonl wins when present
    with pytest.raises(ShapeMoveError, match="not a built dataset"):
        known_actions(tmp_path / "nothing")
