"""A bank of everyday phrasings per canonical action, and the training captions drawn from it.

The archives' labels give each clip a few templated captions (``captions.py``). A person typing a
prompt uses other words: "strides along", "does a handstand-wheel", "a quick one-two". The bank
writes, for every action of ``actions.ACTIONS``, many verb phrases (third person present:
"jogs along"), noun phrases ("a light jog") and typical agents ("a runner"), and ``sentence``
turns one of them into a sentence of a random shape: "{subject} {vp}.", "{subject} is {vp-ing}.",
imperative "{Vp}.", "Make the character {vp}.", "Show {subject} {vp-ing}.", "{Noun}.",
"{subject} does {noun}." ...

Training (T5 and TMA) replaces a clip's stored caption by a bank sentence with probability
``BANK_SHARE`` when the clip's meta names one action, or a sequence of actions ("A, then B"); clips
with several simultaneous actions, and the share left, keep their stored captions (which carry the
styles: "angrily", "like an old person"). ``training_caption`` is that choice; ``known_sentences``
gives a fixed sample per action for the model's known-texts table (what the prompt warning compares
against). The held-out paraphrase sets (``configs/heldout_paraphrases*.json``) were never used to
write or tune this bank.
"""
from __future__ import annotations

import random

from .actions import ACTIONS
from .captions import _tidy, base_form, progressive

BANK_SHARE = 0.5

# subjects any action can take (lower case; the sentence is capitalised when it is written)
SUBJECTS = ["a person", "someone", "a man", "a woman", "the person", "a guy", "a girl", "a boy", "a kid",
            "a child", "an old man", "an elderly woman", "a young man", "a young woman", "a lady", "the character",
            "the actor", "a figure", "an adult", "a teenager", "the avatar", "he", "she", "the man", "the woman",
            "somebody", "a human", "the subject", "a performer", "the model"]
# objects of "make X ..." / "have X ..."
OBJECTS = ["the character", "the avatar", "the person", "him", "her", "the model", "the figure", "the body",
           "the actor", "the rig"]


def _e(vps, nouns=(), agents=()):
    return {"vps": list(vps), "nouns": list(nouns), "agents": list(agents)}


# action -> verb phrases (3rd person present), noun phrases, typical agents
BANK = {
    "walk": _e(["walks", "walks forward", "walks ahead", "strides forward", "walks along", "takes a few steps forward",
                "strolls forward", "walks at a normal pace", "goes for a walk", "walks straight", "moves forward on foot",
                "steps forward", "walks casually", "walks slowly forward", "wanders forward", "saunters along"],
               ["a walk", "a short walk", "a casual walk", "a stroll", "a few steps forward", "a walking motion",
                "a normal walk cycle"],
               ["a walker", "a shopper", "a commuter", "an office worker", "a student"]),
    "walk backward": _e(["walks backward", "walks backwards", "steps backward", "backs up", "moves backwards",
                         "walks in reverse", "takes steps back", "retreats backward", "backpedals"],
                        ["a backward walk", "a few steps back", "a walk in reverse", "backpedaling"]),
    "sidestep": _e(["sidesteps", "walks sideways", "steps to the side", "side-steps to the left",
                    "side-steps to the right", "moves sideways", "shuffles sideways", "steps sideways a few times",
                    "walks to the side", "moves to the left with side steps"],
                   ["side steps", "a sidestep", "a few steps to the side", "a lateral shuffle"],
                   ["a defender", "a basketball defender"]),
    "turn": _e(["turns around", "turns to face the other way", "turns back", "turns on the spot", "spins round to face backwards",
                "turns left", "turns right", "rotates to face behind", "makes a u-turn", "does an about turn"],
               ["a turn", "a half turn", "an about turn", "a u-turn", "a turn on the spot"]),
    "walk in a circle": _e(["walks in a circle", "goes around in a circle", "walks around in circles", "circles around",
                            "walks a circular path", "walks round in a loop", "walks around a circle",
                            "paces in a circle"],
                           ["a walk in a circle", "a circular walk", "a loop on foot", "laps in a circle"]),
    "walk in a figure eight": _e(["walks in a figure eight", "walks a figure-eight path", "walks in a figure 8",
                                  "follows a figure-eight route", "walks two loops in an eight shape"],
                                 ["a figure-eight walk", "a figure 8 path", "a walk in the shape of an eight"]),
    "run": _e(["runs", "runs forward", "runs ahead", "runs fast", "runs straight ahead", "runs quickly",
               "goes for a run", "takes off running", "rushes forward", "hurries forward at a run", "runs a short distance",
               "races forward"],
              ["a run", "a quick run", "a short run", "a running motion", "a run cycle"],
              ["a runner", "an athlete", "a jogger in a hurry"]),
    "jog": _e(["jogs", "jogs forward", "goes for a jog", "jogs along", "jogs slowly", "runs at an easy pace",
               "jogs in place", "runs lightly", "does a slow run", "jogs at a relaxed pace", "trots forward"],
              ["a jog", "a light jog", "a slow jog", "an easy run", "a gentle trot", "a jogging motion"],
              ["a jogger", "a runner"]),
    "sprint": _e(["sprints", "dashes forward at full speed", "sprints forward", "runs as fast as possible",
                  "dashes ahead", "runs at full speed", "bursts forward at top speed", "races at full pace",
                  "sprints a short distance"],
                 ["a sprint", "a dash", "a full-speed run", "an all-out sprint", "a fast dash"],
                 ["a sprinter", "a track athlete"]),
    "march": _e(["marches", "marches forward", "marches in place", "walks with high knees like a soldier",
                 "marches with swinging arms", "stamps forward in step", "parades forward"],
                ["a march", "a military march", "marching steps"],
                ["a soldier", "a drum major", "a guard"]),
    "limp": _e(["limps", "walks with a limp", "limps forward", "drags one leg while walking", "walks on an injured leg",
                "hobbles forward", "walks unevenly favouring one leg", "limps along painfully"],
               ["a limp", "a limping walk", "an injured walk"],
               ["an injured man", "a wounded soldier", "a hurt person"]),
    "sneak": _e(["sneaks forward", "walks stealthily", "creeps forward", "sneaks around", "tiptoes forward",
                 "moves quietly on tiptoe", "prowls forward", "creeps along quietly", "walks carefully without a sound",
                 "sneaks up on someone"],
                ["a sneaky walk", "a stealthy walk", "a quiet tiptoe", "sneaking steps"],
                ["a spy", "a ninja", "a thief"]),
    "zombie walk": _e(["walks like a zombie", "shuffles along like a zombie", "staggers forward with arms out",
                       "lurches forward like a zombie", "walks stiffly with arms stretched forward",
                       "drags itself forward like the walking dead"],
                      ["a zombie walk", "a zombie shuffle", "an undead stagger"],
                      ["a zombie", "a ghoul", "a monster"]),
    "crawl": _e(["crawls on hands and knees", "crawls forward", "crawls", "crawls along the floor",
                 "moves forward on all fours", "creeps along the ground on hands and knees", "crawls slowly"],
                ["a crawl", "crawling on all fours", "a hands-and-knees crawl"],
                ["a baby", "a toddler", "a soldier"]),
    "jump": _e(["jumps", "jumps up", "jumps in place", "jumps straight up", "leaps up", "jumps up high",
                "springs up", "jumps into the air", "jumps with both feet", "leaps into the air"],
               ["a jump", "a vertical jump", "a high jump in place", "a leap"],
               ["a basketball player", "a jumper"]),
    "jump forward": _e(["jumps forward", "does a long jump", "jumps forward with both feet", "leaps forward",
                        "jumps as far as possible", "jumps across", "jumps over a gap", "leaps ahead"],
                       ["a long jump", "a forward jump", "a standing long jump", "a leap forward"],
                       ["a long jumper"]),
    "spin jump": _e(["jumps and turns in the air", "does a spinning jump", "jumps and spins around",
                     "jumps with a full turn", "does a jump turn", "spins in the air while jumping",
                     "jumps and rotates in mid-air"],
                    ["a spinning jump", "a jump turn", "a 360 jump", "a turning jump"],
                    ["a figure skater", "a dancer"]),
    "hop": _e(["hops", "hops on both feet", "hops on one foot", "hops in place", "hops forward",
               "does small jumps", "bounces up and down", "hops a few times"],
              ["a hop", "little hops", "small jumps", "a bunny hop"],
              ["a child", "a kid"]),
    "jumping jacks": _e(["does jumping jacks", "does star jumps", "jumps while spreading the arms and legs",
                         "does a set of jumping jacks", "does jumping jack exercises"],
                        ["jumping jacks", "star jumps", "a set of jumping jacks", "a jumping jack workout"],
                        ["a gym student", "a fitness trainer", "an athlete warming up"]),
    "backflip": _e(["does a backflip", "flips backward", "does a back somersault", "flips over backwards",
                    "does a back tuck", "jumps and flips backwards"],
                   ["a backflip", "a back flip", "a back somersault", "a backward flip"],
                   ["a gymnast", "an acrobat", "a stunt performer"]),
    "sideflip": _e(["does a side flip", "flips sideways", "does a sideways somersault", "flips to the side in the air",
                    "jumps and flips sideways"],
                   ["a side flip", "a sideways flip", "a side somersault"],
                   ["a gymnast", "an acrobat"]),
    "cartwheel": _e(["does a cartwheel", "turns a cartwheel", "does a cartwheel to the side",
                     "wheels sideways over the hands", "flips sideways onto the hands and back to the feet",
                     "cartwheels across the floor"],
                    ["a cartwheel", "a gymnastic cartwheel"],
                    ["a gymnast", "a child", "an acrobat"]),
    "roll": _e(["rolls on the ground", "does a forward roll", "rolls forward on the ground", "does a somersault on the floor",
                "tumbles forward", "rolls over on the floor", "does a roll on the mat"],
               ["a forward roll", "a roll", "a somersault on the ground", "a tumble"],
               ["a gymnast", "a stuntman"]),
    "get up": _e(["gets up from the ground", "stands up from the floor", "gets up off the floor", "gets back on the feet",
                  "rises from the ground", "stands up after lying down", "picks himself up off the floor",
                  "climbs back to standing"],
                 ["getting up from the floor", "a stand-up from lying down"]),
    "lie down": _e(["lies down on the floor", "lies down", "lies down on the back", "gets down and lies flat",
                    "lays down on the ground", "stretches out on the floor", "goes down to lie on the floor"],
                   ["lying down on the floor", "a lie-down"]),
    "sit": _e(["sits down", "sits", "sits down on a chair", "takes a seat", "sits on the floor", "sits down to rest",
               "lowers into a seat", "sits on a stool"],
              ["sitting down", "a sit-down"]),
    "climb": _e(["climbs", "climbs up", "climbs a ladder", "climbs up a wall", "climbs up the rungs",
                 "scrambles up", "climbs hand over hand"],
                ["a climb", "ladder climbing"],
                ["a climber", "a firefighter"]),
    "hang": _e(["hangs from a bar", "hangs by the hands", "dangles from a bar", "holds on to an overhead bar"],
               ["hanging from a bar"]),
    "swing": _e(["swings from a bar", "swings on a bar", "swings back and forth from a bar",
                 "swings the legs while hanging"],
                ["a swing on a bar"]),
    "squat": _e(["does a squat", "squats down", "squats", "squats down and stands up again", "does squats",
                 "bends the knees and lowers the hips", "crouches down and rises", "does deep squats"],
                ["a squat", "squats", "a deep squat", "a bodyweight squat", "a squat exercise"],
                ["a weightlifter", "a gym goer"]),
    "bend over": _e(["bends over", "bends down", "bends forward", "leans over forward", "bends at the waist",
                     "bends down toward the feet"],
                    ["a forward bend", "a bend at the waist"]),
    "pick up": _e(["picks something up from the floor", "picks up an object", "picks something up", "lifts a box off the floor",
                   "bends down and grabs something from the ground", "picks an item up off the ground"],
                  ["picking something up", "a pick-up from the floor"],
                  ["a warehouse worker", "a mover"]),
    "put down": _e(["puts something down on the floor", "puts something down", "sets an object down on the ground",
                    "places something on the floor", "lowers a box to the floor", "bends down to put something down"],
                   ["putting something down", "setting a box down"],
                   ["a warehouse worker", "a mover"]),
    "reach up": _e(["reaches up high", "reaches up and grabs something", "reaches for something above",
                    "stretches up to grab something", "reaches up to a high shelf", "grabs something overhead"],
                   ["a reach upward", "a grab overhead"]),
    "stretch": _e(["stretches", "does stretches", "stretches the arms", "stretches the body", "does some stretching",
                   "warms up with stretches", "stretches the legs"],
                  ["a stretch", "stretching exercises", "a warm-up stretch", "a stretching routine"],
                  ["an athlete", "a yoga student"]),
    "side twist": _e(["does side twists", "twists the upper body from side to side", "twists the torso left and right",
                      "rotates the waist from side to side", "does torso twists"],
                     ["side twists", "torso twists", "waist twists", "a twisting exercise"]),
    "elbow to knee": _e(["touches each elbow to the opposite knee", "brings the elbows to the opposite knees",
                         "does elbow-to-knee crunches", "does standing cross crunches",
                         "lifts a knee to meet the opposite elbow"],
                        ["elbow-to-knee crunches", "standing crunches", "cross-body crunches"]),
    "arm circles": _e(["rotates both arms", "makes circles with the arms", "does arm circles", "circles both arms backward",
                       "swings the arms in circles", "rotates the arms at the shoulders"],
                      ["arm circles", "arm rotations", "shoulder circles"]),
    "balance": _e(["balances on one leg", "stands on one leg", "balances on one foot", "keeps balance on one leg",
                   "lifts one leg and balances"],
                  ["a one-legged balance", "a single-leg stand", "a balance pose"],
                  ["a yoga student", "a gymnast"]),
    "wave": _e(["waves", "waves a hand", "waves hello", "waves at someone", "waves with one hand", "waves both hands",
                "greets someone with a wave", "waves to a friend"],
               ["a wave", "a friendly wave", "a hand wave", "a wave hello"]),
    "wave goodbye": _e(["waves goodbye", "waves bye-bye", "waves farewell", "says goodbye with a wave",
                        "waves goodbye with both hands"],
                       ["a goodbye wave", "a farewell wave"]),
    "raise hand": _e(["raises a hand", "raises a hand up", "raises both hands", "puts a hand up", "lifts an arm up",
                      "raises the arms", "holds a hand up high", "lifts both arms above the head"],
                     ["a raised hand", "hands up", "arms raised"],
                     ["a student", "a pupil"]),
    "bow": _e(["bows", "takes a bow", "bows politely", "bows deeply", "bends forward in a bow", "bows to the audience",
               "gives a polite bow"],
              ["a bow", "a polite bow", "a deep bow"],
              ["a performer", "an actor", "a waiter"]),
    "beckon": _e(["beckons someone to come over", "calls someone over with a hand", "beckons", "waves someone over",
                  "signals someone to come closer", "gestures for someone to approach"],
                 ["a beckoning gesture", "a come-here gesture"]),
    "guide": _e(["guides someone with an open hand", "shows the way with a hand", "points the way with an open hand",
                 "gestures to show someone the way", "directs someone with a sweep of the hand"],
                ["a guiding gesture", "a this-way gesture"],
                ["a host", "a guide", "a receptionist"]),
    "punch": _e(["throws punches", "punches", "punches forward", "throws a punch", "jabs with the fists",
                 "punches the air", "boxes", "throws a left and a right", "hits out with the fists"],
                ["a punch", "a few punches", "a boxing combination", "a jab", "shadow boxing"],
                ["a boxer", "a fighter", "a martial artist"]),
    "kick": _e(["kicks", "kicks with one leg", "kicks forward", "does a front kick", "kicks high", "kicks the air",
                "does a karate kick", "kicks out with the right leg", "kicks out with the left leg"],
               ["a kick", "a front kick", "a high kick", "a karate kick"],
               ["a kickboxer", "a karate fighter", "a martial artist"]),
    "spin kick": _e(["does a spinning kick", "does a spin kick", "spins and kicks", "does a roundhouse kick",
                     "turns around and kicks", "does a spinning back kick"],
                    ["a spin kick", "a spinning kick", "a roundhouse kick", "a turning kick"],
                    ["a martial artist", "a kickboxer"]),
    "slash": _e(["slashes with a sword", "swings a sword", "slashes", "cuts with a sword", "strikes with a blade",
                 "swings a katana", "attacks with a sword"],
                ["a sword slash", "a sword swing", "a blade strike"],
                ["a swordsman", "a samurai", "a knight"]),
    "kick ball": _e(["kicks a ball", "kicks a soccer ball", "kicks the ball forward", "shoots a football with the foot",
                     "kicks a football", "passes a ball with the foot"],
                    ["a kick of the ball", "a soccer kick", "a football shot"],
                    ["a soccer player", "a footballer"]),
    "throw": _e(["throws a ball", "throws a ball forward", "throws something", "tosses a ball", "throws a ball overhand",
                 "throws a basketball"],
                ["a throw", "an overhand throw", "a ball toss"],
                ["a pitcher", "a quarterback", "a player"]),
    "dribble": _e(["dribbles a basketball", "dribbles a ball", "bounces a basketball", "dribbles the ball while moving"],
                  ["basketball dribbling", "a dribble"],
                  ["a basketball player"]),
    "shoot": _e(["shoots a basketball", "takes a shot at the basket", "shoots the ball at the hoop",
                 "jumps and shoots a basketball"],
                ["a basketball shot", "a jump shot", "a free throw"],
                ["a basketball player"]),
    "dance": _e(["dances", "does a dance", "dances happily", "dances to music", "dances around", "moves to the rhythm",
                 "dances energetically", "does a little dance"],
                ["a dance", "a happy dance", "a dance routine", "some dance moves", "a short dance"],
                ["a dancer", "a party guest"]),
    "ballet": _e(["does ballet moves", "dances ballet", "performs ballet", "does a pirouette", "dances like a ballerina",
                  "does a ballet routine"],
                 ["a ballet routine", "ballet steps", "a pirouette"],
                 ["a ballerina", "a ballet dancer"]),
    "spin": _e(["spins around", "turns on the spot", "spins", "twirls around", "spins in place", "turns a full circle",
                "pirouettes"],
               ["a spin", "a twirl", "a full turn on the spot"],
               ["a dancer", "a figure skater"]),
    "pose": _e(["holds a pose", "strikes a pose", "poses", "stands in a pose", "holds a yoga pose", "poses for a photo"],
               ["a pose", "a yoga pose", "a dramatic pose"],
               ["a model", "a yoga student"]),
    "wash": _e(["washes", "takes a shower", "washes the body", "washes up", "scrubs the body in a shower",
                "rinses off under a shower"],
               ["a shower", "washing up"]),
}


def _base_vp(vp: str) -> str:
    """'gets down and lies flat' -> 'get down and lie flat'."""
    words = vp.split()
    out = [base_form(words[0])] if words else []
    for prev, w in zip(words, words[1:]):
        out.append(base_form(w) if prev == "and" and w.endswith("s") and progressive(w) != w else w)
    return " ".join(out)


def _subject(rng: random.Random, entry: dict) -> str:
    if entry["agents"] and rng.random() < 0.3:
        return rng.choice(entry["agents"])
    return rng.choice(SUBJECTS)


def sentence(action: str, rng: random.Random) -> str:
    """One sentence naming ``action`` in a random phrasing and sentence shape."""
    e = BANK.get(action)
    if e is None:  # an action without a bank entry: its phrases from actions.py
        e = _e(ACTIONS[action].phrases if action in ACTIONS else [f"does a {action}"])
    vp = rng.choice(e["vps"])
    subj = _subject(rng, e)
    shapes = ["decl", "decl", "prog", "imp", "make", "show", "fragment"] + (["noun", "noun_do"] if e["nouns"] else [])
    return _tidy(SHAPES[rng.choice(shapes)](subj, vp, e["nouns"], rng))


def _make(vp: str, rng: random.Random) -> str:
    """"make someone walk", "get the figure to walk"."""
    lead = rng.choice(["make", "have", "let", "get"])
    return f"{lead} {rng.choice(OBJECTS)} {'to ' if lead == 'get' else ''}{_base_vp(vp)}."


# the sentence shapes of ``sentence``: (subject, verb phrase, the action's nouns, rng) -> the sentence
SHAPES = {
    "decl": lambda subj, vp, nouns, rng: f"{subj} {vp}.",
    "prog": lambda subj, vp, nouns, rng: f"{subj} is {progressive(vp)}.",
    "imp": lambda subj, vp, nouns, rng: f"{_base_vp(vp)}.",
    "make": lambda subj, vp, nouns, rng: _make(vp, rng),
    "show": lambda subj, vp, nouns, rng:
        f"{rng.choice(['show', 'animate', 'generate', 'a clip of', 'an animation of'])} {subj} {progressive(vp)}.",
    "fragment": lambda subj, vp, nouns, rng: f"{subj} {progressive(vp)}.",
    "noun": lambda subj, vp, nouns, rng: f"{rng.choice(nouns)}.",
    "noun_do": lambda subj, vp, nouns, rng: f"{subj} {rng.choice(['does', 'performs', 'does', 'shows'])} {rng.choice(nouns)}.",
}


def sequence_sentence(actions: list[str], rng: random.Random) -> str:
    """"A, then B" for a sequence of actions, each in a random phrasing."""
    e0 = BANK.get(actions[0]) or _e(ACTIONS[actions[0]].phrases)
    subj = _subject(rng, e0)
    vps = [rng.choice((BANK.get(a) or _e(ACTIONS[a].phrases))["vps"]) for a in actions]
    joiner = rng.choice([", then ", " and then ", ", and after that ", " before it ", ", followed by "])
    if joiner == " before it ":
        return _tidy(f"{subj} {vps[0]} before {progressive(vps[1])}." if len(vps) == 2 else
                     f"{subj} {', '.join(vps[:-1])}, then {vps[-1]}.")
    if joiner == ", followed by ":
        return _tidy(f"{subj} {', '.join(vps[:-1])}, followed by {progressive(vps[-1])}.")
    return _tidy(f"{subj} {', '.join(vps[:-1])}{joiner}{vps[-1]}.")


def training_caption(stored: list[str], labels: dict | None, rng: random.Random, share: float = BANK_SHARE) -> str:
    """The caption of one training example: with probability ``share`` a bank sentence of the clip's
    action (or its sequence of actions), otherwise one of the clip's stored captions."""
    labels = labels or {}
    seq = [a for a in (labels.get("sequence") or []) if a in ACTIONS]
    acts = [a for a in (labels.get("actions") or []) if a in ACTIONS]
    if share > 0 and rng.random() < share:
        if len(seq) >= 2:
            return sequence_sentence(seq, rng)
        if len(acts) == 1:
            return sentence(acts[0], rng)
    return rng.choice(stored) if stored else (sentence(acts[0], rng) if acts else "A person moves.")


def known_sentences(action: str, n: int = 40, seed: int = 0) -> list[str]:
    """A fixed sample of ``n`` distinct bank sentences for ``action`` (the known-texts table)."""
    rng = random.Random(f"{seed}/{action}")
    out: list[str] = []
    for _ in range(n * 5):
        s = sentence(action, rng)
        if s not in out:
            out.append(s)
        if len(out) == n:
            break
    return out
