"""What a prompt asks of each body part (core/generation/part_prompts.py): two things at once split
into a legs prompt and an arms prompt; a named side read, a direction not mistaken for one."""
from __future__ import annotations

import pytest

from shapemove.core.plan.part_prompts import named_side, plan_parts


@pytest.mark.parametrize("text, legs, arms, acts", [
    ("a woman jogs along, waving her left hand", "a woman jogs along", "a person waving her left hand", ("jog", "wave")),
    ("She waves as she walks.", "she walks", "she waves", ("walk", "wave")),
    ("he sprints and punches the air", "he sprints", "a person punches the air", ("sprint", "punch")),
    ("a person walks backwards beckoning", "a person walks backwards", "a person beckoning", ("walk backward", "beckon")),
    ("a man marches while throwing a ball", "a man marches", "a person throwing a ball", ("march", "throw")),
    # "back and forth" is a course, not two clauses ("walks back" + "forth waving" before)
    ("a person walks back and forth waving", "a person walks back and forth", "a person waving", ("walk", "wave")),
    ("a man jogs to and fro and waves", "a man jogs to and fro", "a person waves", ("jog", "wave")),
    # a subject the table does not list is kept: no "a person" put before "a coach"
    ("a coach runs ahead, waving to the team", "a coach runs ahead", "a person waving to the team", ("run", "wave")),
    # "with" says how an action is done; the clauses are joined at "while", ",": not cut at the "with"
    ("a man waves with his right hand while walking slowly", "a person walking slowly", "a man waves with his right hand",
     ("walk", "wave")),
    ("marching with high knees, he waves both hands", "a person marching with high knees", "he waves both hands",
     ("march", "wave")),
    ("a woman jogs with her arms raised", "a woman jogs", "a person her arms raised", ("jog", "raise hand")),
    # a sit carries a gesture as a gait does: the gesture made seated
    ("a woman sits down and waves", "a woman sits down", "a person waves", ("sit", "wave")),
    ("a man sits down while waving", "a man sits down", "a person waving", ("sit", "wave")),
    # a hop, a jump, a squat leave the arms free: "hops while waving" hopped and dropped the wave
    ("a child hops while waving", "a child hops", "a person waving", ("hop", "wave")),
    ("a man jumps and waves", "a man jumps", "a person waves", ("jump", "wave")),
    ("a woman squats while raising both arms", "a woman squats", "a person raising both arms", ("squat", "raise hand")),
])
def test_two_things_split_into_a_legs_and_an_arms_prompt(text, legs, arms, acts):
    plan = plan_parts(text)
    assert plan is not None
    assert (plan.legs_prompt, plan.arms_prompt) == (legs, arms)
    assert (plan.legs_action, plan.arms_action) == acts


def test_the_arms_clause_carries_its_side():
    assert plan_parts("a woman jogs along, waving her left hand").arms_side == ("left", "hand")
    assert plan_parts("someone walks and waves the right arm").arms_side == ("right", "hand")
    assert plan_parts("a person jogs forward and waves").arms_side is None


@pytest.mark.parametrize("text", [
    "a person walks forward",             # one action
    "a person waves",                     # one action
    "a person walks and then waves",      # a sequence is the timeline's job
    "someone waves, after that he runs",
    "a person runs and jumps",            # two locomotions: no arms gesture
    "a person kicks and punches",         # no locomotion
    "a man jumps, then waves",            # in order: the timeline's
    "a man sits down and lies down",      # a sit and another change of posture: one after the other
])
def test_not_two_things_at_once(text):
    assert plan_parts(text) is None


@pytest.mark.parametrize("text, side", [
    ("raise your left hand", ("left", "hand")),
    ("kick with the right foot", ("right", "foot")),
    ("a man kicks left", ("left", "foot")),
    ("punches with the left", ("left", "hand")),
    ("a left-handed throw", ("left", "hand")),
    ("lifts the right knee high", ("right", "foot")),
    ("the person raises their right arm", ("right", "hand")),
    ("steps right with the left foot", ("left", "foot")),
    ("turns left and waves", None),
    ("walks to the right", None),
    ("a person turns right", None),
    ("waves with both the left and right hands", None),
    ("a person waves", None),
])
def test_named_side(text, side):
    assert named_side(text) == side


@pytest.mark.parametrize("text, acts", [
    ("she walks around in a circle holding one hand up", ("walk in a circle", "raise hand")),  # the longer span
    ("a guide walks ahead and beckons the tourists", ("walk", "beckon")),   # not the noun at the front
])
def test_each_part_takes_the_most_specific_action_of_its_own_clause(text, acts):
    plan = plan_parts(text)
    assert plan is not None and (plan.legs_action, plan.arms_action) == acts


def test_clauses_the_patterns_miss_are_classified_when_they_say_what_someone_does():
    """A clause the action patterns do not know goes to ``classify`` when it has a verb: one of
    the caption tables', a participle, a verb after its subject ("the player hurls") or leading
    the clause ("tosses the ball"); a clause of manner ("like an old man") never does."""
    asked = []

    def classify(clauses):
        asked.extend(clauses)
        return ["throw" if ("hurls" in c or "tosses" in c) else "sneak" if "tiptoes" in c
                else "arm circles" if "circles" in c else None for c in clauses]

    plan = plan_parts("Walking backwards, the player hurls a stone.", classify)
    assert plan is not None and (plan.legs_action, plan.arms_action) == ("walk backward", "throw")
    assert plan.arms_prompt == "the player hurls a stone"
    plan = plan_parts("A thief tiptoes along and tosses the keys", classify)   # neither part in the patterns
    assert plan is not None and (plan.legs_action, plan.arms_action) == ("sneak", "throw")
    # the patterns read "around in circles" as a circle walk; with the arms named, the clause is asked
    plan = plan_parts("Marching in place while swinging the arms around in circles", classify)
    assert plan is not None and (plan.legs_action, plan.arms_action) == ("march", "arm circles")
    asked.clear()
    assert plan_parts("a person waves, like an old man", classify) is None
    assert asked == []
