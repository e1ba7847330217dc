"""The words a prompt is read by: one table of word classes, each defined once.

Every class is a compiled pattern (or a table) and a line in ``WORD_CLASSES`` that says what it
means to the plan (``plan.py``), with an example prompt that ``tests/test_plan_vocabulary.py``
reads. The actions themselves (walk, wave, kick, ...) are the dataset's action patterns
(``data/actions.py``: one vocabulary for captions, labels and prompts); the words below say how,
where, how far, how many times, in which order and with which side.

Only ``core/plan`` matches these against a prompt (``reader.py``, ``part_prompts.py``,
``segments.py``); everything downstream reads the plan they make.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from ..text.shape_words import CHILD_WORDS, FEMALE_WORDS, MALE_WORDS

# -- numbers ------------------------------------------------------------------------------------
NUMBERS = {"a": 1, "one": 1, "a single": 1, "two": 2, "a couple of": 2, "a couple": 2, "three": 3, "a few": 3,
           "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}   # "three steps" too
TIMES = {"once": 1, "twice": 2, "thrice": 3}
# the number words as a regex alternation, longest first; QUANTITY without "a" ("a person jumps" counts nothing)
NUMBER_WORDS = "|".join(sorted(map(re.escape, NUMBERS), key=len, reverse=True))
QUANTITY = "|".join(sorted(map(re.escape, set(NUMBERS) - {"a"}), key=len, reverse=True))

# -- a count of a countable action ("jumps twice", "does three squats") ----------------------------
COUNT_TIMES = re.compile(rf"\b(?:(once|twice|thrice)|({QUANTITY}|\d{{1,2}})\s+(?:times\b|(?:\w+\s+)?(?:jump|hop|leap|squat|kick)\w*))",
                         re.I)
# the countable actions and what counts them (``generation/count_words.MEASURES``)
COUNTED = {"jump": "flights", "jump forward": "flights", "spin jump": "flights", "hop": "flights",
           "jumping jacks": "raises", "squat": "dips", "kick": "kicks"}
MAX_COUNT = 12
# seconds a repetition takes: the median start-to-start of repetitions in a row in the built-in
# library's takes (jumping jacks, jumps, jumps forward; 2026-11-29), a lone squat take's length, a
# lone front kick's busy stretch (HDM05); a spin jump as a jump forward, a hop as a jump (no take
# repeats them)
REPETITION_SECONDS = {"jump": 0.7, "jump forward": 1.7, "spin jump": 1.7, "hop": 0.7, "jumping jacks": 1.1,
                      "squat": 1.4, "kick": 1.5}

# seconds a change of posture takes, its start to lying still: the median, over the built-in library's
# 14 lie-down takes, from the root's first drop (below 0.9 of its standing height) to the take's end
# (2026-11-29); a get-up (2.9 s, two takes) fits the 3 s of a segment
POSTURE_SECONDS = {"lie down": 5.3}

# -- pace -------------------------------------------------------------------------------------
FAST = re.compile(r"\b(quick(?:ly)?|fast(?:er)?|brisk(?:ly)?|rapid(?:ly)?|swift(?:ly)?|hurried(?:ly)?|hurr(?:y|ies|ying)|"
                  r"hast(?:y|ily)|speedy|full speed|top speed|flat out|as fast as)\b", re.I)
SLOW = re.compile(r"\b(slow(?:ly|er)?|leisurely|lazily|sluggish(?:ly)?|unhurried(?:ly)?|"
                  r"(?:easy|gentle|relaxed|snail's|leisurely|slow) pace)\b", re.I)

# -- manner: how an action is done, as the captures say it --------------------------------------------
# The data's styles (Bandai's style labels and CMU's style words, written into their captions by
# ``data/captions.py``): the manner a prompt asks ("walks proudly", "a tired man walks") and a captured
# take's own (``manner_of`` its captions), read by the same patterns. Looked for in this order, the
# first found wins ("energetically, with youthful vigour": youthful; "stiffly, like an old person": old).
MANNERS = {
    "youthful": r"youthful(?:ly)?|with youthful vigou?r",
    "old": r"like an? (?:old|elderly) (?:person|man|woman|lady|gentleman)|(?:old|elderly|aged) "
           r"(?:person|man|woman|lady|gentleman|people|men|women)|grand(?:ma|pa|mother|father)|granny",
    "stiff": r"stiff(?:ly)?|as if aching",
    "happy": r"happ(?:y|ily)|cheerful(?:ly)?|joyful(?:ly)?|gleeful(?:ly)?",
    "sad": r"sad(?:ly)?|gloom(?:y|ily)|dejected(?:ly)?|depressed|sorrowful(?:ly)?|mournful(?:ly)?",
    "angry": r"angr(?:y|ily)|furious(?:ly)?|in anger|enraged",
    "proud": r"proud(?:ly)?|with pride|(?<!not )confident(?:ly)?|strut(?:s|ting|ted)?",
    "timid": r"timid(?:ly)?|without confidence|unconfident(?:ly)?|shy(?:ly)?|nervous(?:ly)?|hesitant(?:ly)?",
    "scared": r"fearful(?:ly)?|scared|afraid|frightened",
    "tired": r"tired(?:ly)?|wear(?:y|ily)|exhausted|with exhaustion",
    "childish": r"childish(?:ly)?|childlike|like a (?:little )?(?:child|kid)",
    "masculine": r"masculine|in a (?:manly|masculine) (?:way|manner)|manly|macho",
    "feminine": r"feminine|in a (?:feminine|girlish|ladylike) (?:way|manner)|girlish(?:ly)?|ladylike",
    "energetic": r"energetic(?:ally)?|active(?:ly)?|vigorous(?:ly)?|lively|excited(?:ly)?|enthusiastic(?:ally)?|eager(?:ly)?",
    "rhythmic": r"rhythmic(?:al)?(?:ly)?|like in a musical",
    "giant": r"like a giant|with heavy steps|heavy-footed|lumbering",
    "swagger": r"(?:with a )?swagger(?:ing|s)?|like a (?:street )?thug|coolly",
    "exaggerated": r"exaggerated|extravagant(?:ly)?|dramatic(?:ally)?|with (?:large|big|huge) steps",
    "clumsy": r"clums(?:y|ily)",
    "careful": r"careful(?:ly)?|cautious(?:ly)?",
    "seductive": r"seductive(?:ly)?|sexy",
}
MANNER_PATTERNS = {k: re.compile(r"\b(?:" + v + r")\b") for k, v in MANNERS.items()}
MANNER = re.compile(r"\b(?:in an? )?(?:" + "|".join(MANNERS.values()) + r")(?: (?:way|manner|fashion))?\b")   # the words taken
MANNER_SAID = {"youthful": "youthfully", "old": "like an old person", "stiff": "stiffly", "happy": "happily",
               "sad": "sadly", "angry": "angrily", "proud": "proudly", "timid": "timidly", "scared": "fearfully",
               "tired": "wearily", "childish": "childishly", "masculine": "in a masculine way",
               "feminine": "in a feminine way", "energetic": "energetically", "rhythmic": "rhythmically",
               "giant": "like a giant", "swagger": "with a swagger", "exaggerated": "with exaggerated strides",
               "clumsy": "clumsily", "careful": "carefully", "seductive": "seductively"}

# -- stop, steps, distance, standing still ------------------------------------------------------
# the arms brought down after a raise ("raises her arms, then lowers them slowly"): the raise's own end,
# which its captured takes perform (``segments.split_segments``)
RAISES = frozenset({"raise hand", "reach up"})
LOWERED = re.compile(r"(?:slowly\s+)?(?:lower(?:s|ing)?|drop(?:s|ping)?|brings?\s+(?:them|it|(?:his|her|their|both|the)\s+"
                     r"(?:arms?|hands?))\s+(?:back\s+)?down)\b(?:\s+(?:them|it|(?:his|her|their|both|the)\s+(?:arms?|hands?)))?"
                     r"(?:\s+(?:again|slowly|back down|down|to (?:his|her|their) sides?))*\s*$")
# how a stop is made, said after it ("stops suddenly", "comes to a sudden halt", "stops dead in his tracks")
STOP_HOW = r"(?:\s+(?:suddenly|abruptly|sharply|quickly|short|dead|immediately|briefly|slowly|gradually|completely))?" \
           r"(?:\s+in (?:his|her|their|its) tracks)?"
STOP_NOUN = r"(?:(?:sudden|quick|full|complete|abrupt|dead|gradual)\s+)?(?:stop|halt|standstill)"
STOP = re.compile(r"\s*(?:,\s*)?(?:\b(?:and|then)\s+)*(?:\b(?:he|she|they|it)\s+)?"
                  r"(?<!bus )(?<!the )(?<!\ba )(?<!next )(?<!last )(?<!first )(?<!pit )(?<!full )(?<!tram )(?<!train )"
                  r"\b(?:stops?(?:\s+(?:walking|running|jogging|moving))?|halts?|comes? to a " + STOP_NOUN + r"|"
                  r"stands? still|stays? still)\b" + STOP_HOW + r"(?:\s+(?:there|still))?\s*\.?\s*$")
# a stop between two things ("walks forward, stops, and waves", "runs, stops and looks back"): the gait's
# own stop, then what follows (``segments.split_segments`` orders it as "walks forward, then stops, then waves")
MID_STOP = re.compile(r"(?:\s*,\s*|\s+and\s+)(?:(?:he|she|they|it)\s+)?(stops?|halts?|comes?\s+to\s+an?\s+" + STOP_NOUN + r")"
                      + STOP_HOW + r"\b\s*(?:,\s*)?(?:and\s+)?(?:then\s+)?(?=[a-z])")
NOT_STOPPING = re.compile(r"\b(?:without stopping|non-?stop|never stops?|doesn't stop|does not stop)\b")
STEPS = re.compile(r"\b(" + NUMBER_WORDS + r"|\d{1,2})\s+"
                   r"(?:\w+\s+)?(?:steps?|strides?|paces?)\b")
# a count alone ("takes three steps forward", no stop word): "a" only right before the step ("a man steps
# aside" counts nothing)
STEPS_ALONE = re.compile(r"\b(" + QUANTITY + r"|\d{1,2})\s+(?:\w+\s+)?(?:steps?|strides?|paces?)\b|"
                         r"\b(a)\s+(?:single\s+|small\s+|big\s+|quick\s+|short\s+|long\s+)?step\b")   # not "a brisk pace"
STILL = re.compile(r"\b(?:stands?|standing) (?:still|there|idle|motionless|quietly|around)\b|\b(?:stays?|staying) "
                   r"(?:still|put)\b|\b(?:waits?|waiting|pauses?|pausing|stops?|halts?|idles?|idling|rests?|resting)\b|"
                   r"\b(?:holds?|holding) still\b")
UNITS = {"m": 1.0, "metre": 1.0, "meter": 1.0, "metres": 1.0, "meters": 1.0, "feet": 0.3048, "foot": 0.3048,
         "ft": 0.3048, "yard": 0.9144, "yards": 0.9144, "yd": 0.9144, "yds": 0.9144}
DISTANCE = re.compile(r"\b(\d{1,3}(?:\.\d+)?|" + NUMBER_WORDS +
                      r")\s*(" + "|".join(sorted(UNITS, key=len, reverse=True)) + r")\b"
                      r"(?![-\s]*(?:tall|high|in height|long|wide|deep|man|woman|person|guy|girl|boy|lady|kid|child|"
                      r"giant|figure|athlete|soldier|dancer|player)\b)")
SPOKEN_DISTANCE = re.compile(r"\s*\b(?:(?:for|about|around|some|roughly|nearly|almost|another)\s+)*" + DISTANCE.pattern,
                             re.I)   # "for about 5 m": what the gait is sampled without
GAITS = {"walk", "run", "jog", "sprint", "sneak", "march", "limp", "walk backward", "sidestep", "zombie walk"}
MAX_METRES = 100.0
MAX_STEPS = 20
NUMBER = re.compile(r"\d+(?:[.,]\d+)?(?:\s*(?:[a-z]+\.?|'|\"))?")   # "10 m", "5 seconds": not a body's words

# -- how long ("for ten seconds", "for 5 s", "for half a minute", "a 10-second jog") ----------------
TIME_UNITS = {"second": 1.0, "seconds": 1.0, "sec": 1.0, "secs": 1.0, "s": 1.0,
              "minute": 60.0, "minutes": 60.0, "min": 60.0, "mins": 60.0}
_TIME_UNIT = "|".join(sorted(map(re.escape, TIME_UNITS), key=len, reverse=True))
DURATION = re.compile(r"\bfor\s+(?:(?:about|around|roughly|some|nearly|almost|another|a\s+good)\s+)?"
                      r"(?:(half)\s+a|(\d{1,3}(?:\.\d+)?)|(" + NUMBER_WORDS + r"))\s*(" + _TIME_UNIT + r")\b|"
                      r"\b(\d{1,2}|" + QUANTITY + r")[-\s](second|minute)\b(?=\s+\w)", re.I)
MIN_SECONDS, MAX_SECONDS = 0.4, 60.0   # a length said outside these is not one the generator makes

# -- courses ----------------------------------------------------------------------------------
CLOCKWISE = re.compile(r"(?<![-\w])(?:clockwise|to (?:the|his|her|their|its|your) right|rightward)\b")
COUNTER_CLOCKWISE = re.compile(r"\b(?:counter|anti)[- ]?clockwise\b")
# "paces" is back and forth only where nothing sends it on: "paces the room", "is pacing nervously", "paces
# back and forth", "she paces." -- not "paces ahead at a steady clip", "paces along the road"
_TO_AND_FRO = r"back and forth|to and fro|backwards and forwards"
_UP_AND_DOWN = r"up and down the (?:room|hall|hallway|corridor|street|platform|stage)"
_PACE = (r"\bpac(?:es|ing)\b(?=\s+(?:(?:around|about|round)\s+)?(?:the|a|his|her|their)\s+(?:[\w-]+\s+)?(?:room|floor|halls?|"
         r"hallway|corridor|office|cell|stage|platform|deck|yard|kitchen|ward|lobby)\b|\s+(?:nervously|impatiently|"
         r"anxiously|restlessly|worriedly|around|about|back and forth|to and fro|up and down)\b|\s*(?:[,.;!]|$))")
BACK_AND_FORTH = re.compile(rf"\b(?:{_TO_AND_FRO}|{_UP_AND_DOWN})\b|{_PACE}", re.I)
ZIGZAG = re.compile(r"\bzig[- ]?zag(?:s|ging|ged)?\b", re.I)
DIAGONAL = re.compile(r"\bdiagonal(?:ly)?\b|\bat an angle\b", re.I)
# a square walked: "in a square", "around a small square", "a square path" -- not "the town square"
SQUARE = re.compile(r"\b(?:in|around|round|along)\s+a\s+(?:(?:small|big|large|wide|tight)\s+)?square\b(?![- ]?(?:met|foot|feet))"
                    r"|\bsquare[- ](?:shaped\s+)?(?:path|route|pattern|course|loop)\b", re.I)
GOING = re.compile(r"\b(?:go|goes|going|went|move|moves|moving|moved|travel\w*|head\w*)\b", re.I)   # a way gone, no gait named
# a gait that goes to one side: the walker turns that way and goes on ("runs to the left", "jogs off to his
# right"); a step, a shuffle or a slide to one side is a sidestep (``TRAVEL_SIDE``), not a turn
ASIDE = re.compile(r"\b(?:walk|run|jog|sprint|march|sneak|limp|stroll|trot|dash|hurr(?:y|ie)|head|go)(?:s|es|ing|ed)?\b"
                   r"(?:\s+(?:off|away|on|over|quickly|slowly|briskly))?\s+(?:to|towards?)\s+(?:the|his|her|their|its|your)\s+"
                   r"(left|right)\b", re.I)
COURSE_VERB = re.compile(rf"{_PACE}|\bzig[- ]?zag(?:s|ging|ged)\b", re.I)   # the course as the verb: "walks"
# the course in words, cut out for its gait: "in a circle", "around in circles", "a figure-8 path",
# "in a zigzag", "back and forth", "up and down the room"
COURSE_WORDS = re.compile(
    r"(?:\s+(?:around|round|along|on|in|into|through|doing|making|tracing|following))*\s+(?:(?:a|an|the)\s+)?"
    r"(?:(?:small|big|large|wide|tight|full)\s+)?(?:figure[- ]?(?:of[- ])?(?:8|eight)|circles?|zig[- ]?zag|square)"
    r"(?:[- ]shaped)?(?:\s+(?:path|route|pattern|course|shape|loop|line))?\b"
    r"|(?:\s+(?:around|round|in))*\s+an?\s+(?:(?:small|big|large|wide|tight|full)\s+)?loop\b"
    rf"|\s+(?:{_TO_AND_FRO}|diagonally|at an angle)\b|\s+{_UP_AND_DOWN}\b", re.I)
# circles the arms make, not the walk: "rotating your arms in circles", "swinging the arms around in circles"
ARM_CIRCLES = re.compile(r"\b(?:arms?|hands?|fists?|wrists?)\b(?:\s+[\w-]+){0,2}?\s+(?:(?:a)?round\s+)?in\s+"
                         r"(?:(?:big|small|wide|large)\s+)?circles?\b", re.I)
COURSE_WAY = re.compile(r"\s+(?:(?:counter|anti)[- ]?)?clockwise\b|"
                        r"\s+(?:to (?:the|his|her|their|its|your) (?:right|left)|rightwards?|leftwards?)\b",
                        re.I)   # the course's way round, not the gait's ("runs in a circle to the right")
# the courses by name (``generation/course_walk.COURSES`` draws them)
CIRCLE = "walk in a circle"
EIGHT = "walk in a figure eight"
BACK_AND_FORTH_COURSE = "back and forth"
ZIGZAG_COURSE = "zigzag"
SQUARE_COURSE = "square"
ASIDE_COURSE = "aside"
DIAGONAL_COURSE = "diagonal"
COURSE_ACTIONS = (CIRCLE, EIGHT)     # the courses that are actions of the data (``data.actions``)
COURSE_NAMES = {CIRCLE: "in a circle", EIGHT: "in a figure eight"}   # as people say them
COURSE_KINDS = (CIRCLE, EIGHT, BACK_AND_FORTH_COURSE, ZIGZAG_COURSE, SQUARE_COURSE, DIAGONAL_COURSE,
                ASIDE_COURSE)   # every course the plan takes (and the panel offers)

# -- turns ------------------------------------------------------------------------------------
TURN_WHOLE = re.compile(r"\b(?:spins?|spinning|full (?:turn|circle|rotation)|360|all the way (?:a)?round|pirouettes?)\b")
TURN_HALF = re.compile(r"\b(?:turns? (?:a)?round|turning (?:a)?round|turns? back|turning back|about[- ]face|u-turn|180|"
                       r"face the other way|the other direction)\b")
TURN_QUARTER = re.compile(r"\b(?:quarter turn|90|turns? (?:to (?:the|his|her|their) )?(?:left|right)|"
                          r"turning (?:to the )?(?:left|right))\b")
TURN_RIGHT = re.compile(r"\b(?:right|clockwise|rightward)\b")
TURN_NOT_BODY = re.compile(r"\bturn(?:s|ing|ed)? (?:his|her|their|the|its|one's|a) (?!body\b|whole\b)\w+")
TURN_TWICE = re.compile(r"\b(?:twice|two times|two full)\b")
# a count of turns: "spins three times", "turns around 3 times", "four full turns"
TURN_TIMES = re.compile(rf"\b(?:(thrice)|({QUANTITY}|\d{{1,2}})\s+(?:full\s+)?(?:times|turns|spins|rotations))\b")
TURN_NEGATED = re.compile(r"\b(?:without|not|no|never|don't|doesn't|do not|does not|stop)\s+(?:\w+\s+)?(?:turn|spin)")

# -- travel -----------------------------------------------------------------------------------
# "walks back" / "comes back" / "heads back": a return, walked facing the way (not "walks backwards", "steps back")
RETURN = re.compile(r"\b(?:walk|stroll|jog|run|sprint|head|com|go|hurr|wander|march)\w* back(?! and forth| and back)\b(?!-)",
                    re.I)
# "circles her arms backwards", "swings his arms forward": the way the arms go, not the body
_ARMS_WAY = r"(?<!arms )(?<!arm )"
FORWARD = re.compile(r"\b(?:" + _ARMS_WAY + r"forwards?|ahead|onwards?|toward(?:s)? (?:the )?(?:camera|viewer))\b|"
                     + RETURN.pattern, re.I)
BACKWARD = re.compile(r"\b(" + _ARMS_WAY + r"backwards?|in reverse|backs? (?:up|away)|backing (?:up|away)|retreat\w*|"
                      r"(?:steps?|stepping) back(?! and forth))\b", re.I)
IN_PLACE = re.compile(r"\b(in place|on the spot)\b", re.I)
# a jump kept where it is: "jumps straight up", "jumps up and down", "a vertical jump" (not "walks up and down")
JUMP_IN_PLACE = re.compile(r"\b(?:jump|hop|bounc|leap|spring)\w*(?:\s+\w+){0,3}?\s+(?:straight up|up and down|vertically)\b|"
                           r"\bvertical(?:ly)?\s+(?:jump|leap|hop)\w*|\b(?:jump|skip)\w* (?:a |the )?rope\b", re.I)
# actions a length asked keeps going, one after another ("punches for ten seconds": punch after punch);
# not a squat, a pose or a change of posture, which a length may hold
KEPT_UP = frozenset({"punch", "kick", "jump", "jump forward", "hop", "slash"})
# a counted action done again and again, as long as the motion lasts ("jumps up and down", "squats repeatedly")
AGAIN = re.compile(r"\b(?:repeatedly|over and over(?: again)?|again and again|several times|many times|continuously|"
                   r"keeps? (?:on )?\w+ing|up and down|(?:jump|skip)\w* (?:a |the )?rope)\b", re.I)
# a hop or a jump on one foot ("hops on one foot", "on her left leg", "a one-legged hop"): no capture does one
ONE_FOOT = re.compile(r"\b(?:on|with|using) (?:just |only )?(?:one|a single|(?:his|her|their|the|its) (?:left|right)) "
                      r"(?:foot|leg)\b|\bone[- ](?:footed|legged)\b")
ONE_FOOT_ACTIONS = frozenset({"hop", "jump", "jump forward"})
# a side named for travel: a verb of going, then within three words "to the left" / "to his right"
_GOING = (r"\b(?:steps?|stepping|shuffl\w*|walk\w*|mov\w*|slid\w*|glid\w*|crab\w*|strafe\w*|side-?step\w*|run\w*|"
          r"jog\w*|hop\w*|go(?:es|ing)?|cartwheel\w*|roll(?:s|ing|ed)?|jump\w*|leap\w*|tumbl\w*)\b")
TRAVEL_SIDE = re.compile(_GOING + r"(?:\W+\w+){0,3}?\W+(?:to|towards?|over to) (?:the|his|her|their|its|your) (left|right)\b",
                         re.I)
SIDEWAYS = re.compile(_GOING + r"(?:\W+\w+){0,3}?\W+(sideways|sidewards)\b", re.I)

# -- arms held raised: a state ("with both arms raised", "keeps his hand up"), not the act of raising --------
# the hands a gesture is made with: both ("waves with both hands", "raises her hands", "waves his arms") or
# one ("raises a hand", "lifts one hand high", "with his arm up"); a named side is one too
BOTH_HANDS = re.compile(r"\b(?:both|two)\s+(?:of\s+(?:his|her|their|the)\s+)?(?:hands|arms)\b|"
                        r"\b(?:his|her|their|the|its|your|one's)\s+(?:hands|arms)\b")
ONE_HAND = re.compile(r"\b(?:a|one|his|her|their|the|its|your|one's)\s+(?:hand|arm)\b")
ARMS_HELD = re.compile(r"\b(?:with|keeps?|keeping|holds?|holding)\s+(?:[\w-]+\s+){0,2}?(?:arms?|hands?)\s+(?:held\s+)?"
                       r"(?:raised|lifted|up|high|aloft|above(?:\s+(?:his|her|their|the)\s+heads?)?|overhead|in the air)\b|"
                       r"\b(?:arms?|hands?)\s+(?:held\s+)?(?:raised|lifted|aloft|up high)\b")
# a squat held low ("squats and holds it", "crouches down and stays there", "holds the squat")
HELD_LOW = re.compile(r"\b(?:holds?|holding)\s+(?:it|that|this|there|still|(?:the|that|this|her|his|their)\s+"
                      r"(?:position|pose|squat|crouch))\b|\b(?:stays?|staying|remains?|remaining)\s+(?:down|low|there|"
                      r"crouched|squatting|in\s+(?:the|that|this)\s+(?:position|squat|crouch))\b")
HELD_LOW_ACTIONS = frozenset({"squat"})

# -- body parts, sides, subjects, clauses -----------------------------------------------------------
# "and" joins two clauses, not the pairs "back and forth", "to and fro", "up and down", "round and round"
CONNECTOR = re.compile(r",|;|\b(?:while|whilst|as|and(?!\s+(?:forth|fro|forwards|down|round)\b)|with|at the same time|"
                       r"all the while|meanwhile|simultaneously)\b")
# who does it: a pronoun, or a noun of a person (the body words' nouns of either sex and of an age,
# and the roles prompts name) after up to three words ("a short, heavy grandmother")
_OBJECT_PRONOUNS = frozenset({"him", "his", "himself", "her", "hers", "herself"})
PERSON_NOUNS = tuple(dict.fromkeys(
    [w for w in MALE_WORDS + FEMALE_WORDS if w not in _OBJECT_PRONOUNS] + list(CHILD_WORDS) +
    ["person", "someone", "somebody", "they", "people", "teenager", "teen", "adolescent", "pensioner", "soldier",
     "dancer", "athlete", "figure", "character", "actor", "actress", "player", "runner", "walker", "human", "boxer",
     "fighter", "coach", "student", "teacher", "jogger", "hiker", "gymnast", "skater", "climber", "swimmer",
     "worker", "performer", "robot", "zombie", "ninja", "toddler", "thief", "burglar", "spy", "guard", "mailman",
     "postman", "waiter", "officer", "nurse", "doctor", "chef", "cowboy", "pirate", "knight", "goalkeeper",
     "footballer", "i", "you", "we"]))
SUBJECT = re.compile(r"^(?:(?:a|an|the|this|that|one|some|my|our|his|her|their|your)\s+(?:[\w-]+,?\s+){0,3}?)?"
                     r"(?:" + "|".join(sorted(PERSON_NOUNS, key=len, reverse=True)) + r")\b")
HAND_WORDS = r"hand|hands|arm|arms|fist|fists|palm|elbow|shoulder|wrist|finger|fingers"
FOOT_WORDS = r"foot|feet|leg|legs|knee|knees|heel|toe|toes|shin|ankle|thigh"
SIDE = re.compile(r"\b(left|right)\b(?:(?:-|\s+)(?:(?:hand(?:ed)?|arm(?:ed)?|foot(?:ed)?|leg(?:ged)?)\b|"
                  r"(?:\w+\s+){0,1}?(" + HAND_WORDS + "|" + FOOT_WORDS + r")\b))?")
DIRECTION = re.compile(r"\b(?:to|towards?|on) (?:the|his|her|their|your|its) (?:left|right)\b|"
                       r"\b(?:turn|turns|turning|turned|veer|veers|steer|steers|bear|bears|head|heads|go|goes|"
                       r"walk|walks|step|steps|move|moves|look|looks|curve|curves|spin|spins|rotate|rotates)"
                       r"\s+(?:to\s+)?(?:left|right)\b")
ORDER_WORDS = re.compile(r"\b(then|after|afterwards|before|followed by|next|finally|later)\b|"
                         r"^\s*once\s+(?:he|she|they|someone|somebody|i|we|you)\b|^\s*having\s+[^,]{2,40},")   # no two at once

# -- order: segments ----------------------------------------------------------------------------
# words that put what follows after what precedes ("then"): a cut with that order
THEN = re.compile(r"\s*(?:[,;.]\s*)?\b(?:and\s+)?(?:then|after\s+that|afterwards?|after\s+which|next(?!\s+to\b)|finally|"
                  r"(?:(?:a|one|some)\s+(?:few\s+)?(?:moments?|minutes?|seconds?|while)\s+)?(?<!-)(?<!you\s)later(?:\s+on)?|"
                  r"subsequently|eventually|"
                  r"followed\s+by|"
                  r"(?:finish(?:es|ing)?|end(?:s|ing)?)\s+(?:off\s+|up\s+)?(?:with|by)|"
                  r"follow(?:s|ed|ing)?\s+(?:it|this|that|them)\s+(?:up\s+)?with|"
                  r"and\s+(?:finally|afterwards?))\b\s*,?\s*")
# "before" / "after" in front of a clause: a participle or a pronoun follows ("runs after the ball" is no cut)
_CLAUSE_AHEAD = r"(?=[a-z'-]+ing\b|(?:he|she|they|someone|somebody|i|we|you)\b)"
BEFORE_AFTER = re.compile(r"\s*,?\s*\b(before|after)\s+" + _CLAUSE_AHEAD)
# ... and at the start, before a noun phrase and its comma, or a noun phrase and the main clause's subject
# ("after a bow, the actor walks away", "after a long walk she sits down")
# ("once" opening a clause, and "having" with its comma, are an "after": "once she has waved, she runs off",
# "having bowed, the actor walks away")
LEADING_BEFORE_AFTER = re.compile(r"^\s*(?:(before|after)\s+(?:" + _CLAUSE_AHEAD + r"|(?=(?:a|an|the|his|her|their)\s[^,]{1,30},)|"
                                  r"(?=(?:a|an|the|his|her|their)\s(?:[a-z'-]+\s){1,3}(?:he|she|they|someone|somebody|"
                                  r"(?:a|an|the)\s)))|(once)\s+(?=(?:he|she|they|someone|somebody|i|we|you)\b)|(having)\s+(?=[^,]{2,40},))")
# a way to go alone after an order word: the gait before it goes on that way ("runs to the left, then to the
# right" -> "runs to the right")
WAY_ALONE = re.compile(r"^(?:(?:back\s+)?to\s+(?:the|his|her|their|its)\s+(?:left|right)|(?:back|for)wards?|ahead|sideways|"
                       r"(?:the\s+)?other\s+way|"
                       r"(?:with\s+)?(?:the|his|her|their|its)\s+(?:left|right|other)(?:\s+(?:hand|arm|leg|foot|one))?)"
                       r"(?:\s+(?:again|too|as\s+well))?$")   # "raises the right hand, then the left" -> "raises the left"
# a step of a list whose last step an order word starts ("walks ahead, spins around, then waves"): a comma and a verb
LIST_STEP = re.compile(r",\s*(?=[a-z'-]{3,}s\b)")
FIRST = re.compile(r"\b(?:first(?:ly)?|at first|initially|to begin with|to start with)\b\s*,?\s*")
# "and" that orders: a change of posture on one side ("stands up and runs", "walks over and sits down");
# any other "and" joins two things at once or one action ("jumps and twirls": a spin jump)
POSTURE_CHANGES = {"get up": 1.0, "lie down": -1.0, "sit": -1.0}   # the changes of posture: the way the root goes (up, down)
RISEN_FROM = frozenset({"squat", "bend over", "pick up", "put down"})   # "squats, then stands up": the squat's own end
TO_THE_FLOOR = frozenset({"pick up", "put down"})   # actions whose hand goes down to the floor
AND = re.compile(r"\s*,?\s*\band\s+")
PARTICIPLE = re.compile(r"^(?!(?:spring|bring|swing|sing|string|ring|thing|sling|sting|wing|cling|fling)\b)[a-z'-]{2,}ing\b")

# -- words no reader needs to act on (the model reads them with the rest) ---------------------------
SMALL_WORDS = frozenset(
    "a an the this that these those his her their its my your our one some is are was were be being been it he she "
    "they him them who while whilst as and or with of to in on at for from by into onto up down out over around "
    "round about then after before again also just very really while does do did doing does has have having "
    "himself herself themselves itself s me us let make makes show shows like can could will would should may might "
    "must both other others off again so there here all each every no not but if when than too had get gets getting "
    "along".split())
WORD = re.compile(r"[a-z][a-z'-]*")


class WordClass(NamedTuple):
    name: str        # the plan's field it fills (``plan.Words``)
    words: str       # the words, as people say them
    meaning: str     # what the plan makes of them
    example: str     # a prompt that has them (read by ``tests/test_plan_vocabulary.py``)
    expect: dict     # what the example's plan holds (``Words.understood``)


WORD_CLASSES = (
    WordClass("actions", "walk, run, jog, sit down, wave, kick, jump, squat, throw, ... (data/actions.py)",
              "the legs and arms action the model is asked for", "a person sits down", {"actions": ["sit"]}),
    WordClass("legs + arms", "a gait or a sit and a gesture joined by 'and', 'while', ',', 'as', 'with'; a hop, a jump "
              "or a squat and a gesture joined by any of them but 'and'",
              "two things at once: the legs and the arms generated each from its own words",
              "a woman jogs while waving", {"legs": "a woman jogs", "arms": "a person waving"}),
    WordClass("side", "left / right with a hand or foot word, or with an action of one part",
              "the motion mirrored so that side moves", "a man kicks with his left foot", {"side": "left foot"}),
    WordClass("course", "in a circle, in a figure eight, back and forth, zigzag, diagonally (clockwise / to the right), "
              "a gait to the left / right (runs to the left: turns that way and goes on)",
              "the gait walked straight, then bent along the course", "a man walks in a circle clockwise",
              {"course": CIRCLE, "course_way": "right"}),
    WordClass("turn", "turns around / back (180), turns left / right, a quarter turn (90), spins, a full turn (360), twice",
              "the body turned that far about the pelvis", "someone turns around", {"turn_degrees": 180}),
    WordClass("travel", "forward, backwards, steps to the left, sideways",
              "candidates travelling against the words set aside", "a person walks backwards",
              {"travel": "backward"}),
    WordClass("in place", "in place, on the spot (with a gait)", "the gait's strides shortened to stay on the spot",
              "a person jogs in place", {"in_place": True}),
    WordClass("jump in place", "in place, on the spot, straight up, up and down, vertically, jumps rope (with a jump or "
              "a hop)",
              "candidates that travel away set aside: a vertical jump, not a long one", "a boy jumps up and down",
              {"actions": ["jump"], "in_place": True}),
    WordClass("distance", "3 metres, ten meters, 20 feet, 5 yards (with a gait)",
              "the gait cut where it is that far from its start, then standing", "a man walks 3 metres forward",
              {"distance_m": 3.0, "stop": True}),
    WordClass("steps", "three steps, a couple of steps, a step", "the gait cut after that many foot strikes, then standing",
              "she takes three steps forward", {"steps": 3, "stop": True}),
    WordClass("stop", "and stops, then halts, comes to a stop (after a gait)", "the gait cut halfway, then standing",
              "a person walks forward and stops", {"stop": True}),
    WordClass("stand still", "stands still, waits, pauses (and no action)", "the model's standing code",
              "a person stands still", {"stand_still": True}),
    WordClass("length", "for ten seconds, for 5 s, for half a minute, a 10-second jog",
              "the motion (or its segment of a sequence) is that long, unless a length is set", "a man jogs for 8 seconds",
              {"seconds": 8.0}),
    WordClass("count", "once, twice, three times, five jumping jacks (jumps, hops, squats, kicks)",
              "the candidates whose count is nearest the asked one compete", "a man jumps twice", {"count": 2}),
    WordClass("pace", "quickly, briskly, fast / slowly, at a leisurely pace (with a gait)",
              "fast: the fastest third of the candidates; slow: played slower or shorter strides",
              "a woman walks slowly", {"pace": "slow"}),
    WordClass("manner", "proudly, sadly, happily, angrily, timidly, wearily, childishly, like an old person, an old / "
              "a tired / a proud man, like a giant, with a swagger, rhythmically, energetically, ... (``MANNERS``)",
              "the captured takes of the action done so compete, alone (the T5's samples too when none is: it is "
              "said); none asked, the takes done in a manner compete only where no plain one is",
              "a man walks proudly", {"manner": "proud"}),
    WordClass("slowly", "slowly, at a leisurely pace (with an action that is no gait)",
              "the action played at 0.67 of its speed, its held end taken up first (generation/slow_action.py)",
              "an old man sits down slowly", {"slowly": True}),
    WordClass("arms held", "with both arms raised, hands raised, keeps a hand up, holding his arms up high",
              "the arms raised once and held there: the raise played to its highest point, that pose kept for the rest",
              "a man walks with both arms raised", {"arms_held": True, "legs": "a man walks"}),
    WordClass("again", "repeatedly, over and over, again and again, several times, keeps jumping, up and down, "
              "jumps rope (with a jump, a hop, a squat or a kick; no number)",
              "a captured take of one repetition plays it again for as long as the motion lasts",
              "a man squats repeatedly", {"actions": ["squat"], "again": True}),
    WordClass("one foot", "on one foot, on her left leg, one-legged (with a hop or a jump)",
              "said not to be met: every captured hop and jump lands on both feet (generation/one_foot.py)",
              "a child hops on one foot", {"one_foot": True, "actions": ["hop"]}),
    WordClass("order", "then, and then, after that, after which, next, finally, (a minute) later, eventually, "
              "subsequently, followed by, finishes / ends with, follows it with, after / before + a clause, "
              "a list of steps before an order word (walks ahead, spins, then waves), "
              "and beside a change of posture (gets up and walks, walks over and sits down)",
              "segments one after the other, each its share of the length", "a person walks forward, then sits down",
              {"segments": 2}),
)
