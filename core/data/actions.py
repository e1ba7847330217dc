"""The canonical action vocabulary: what the motion data holds, under one name per action.

``ACTIONS`` maps each canonical name ("walk", "jumping jacks", "spin kick", ...) to an ``Action``:
``phrases`` are the verb phrases the caption generator writes for it (third person, present:
"walks forward"), ``patterns`` the regular expressions (lower-case text) that recognise it in a
source's labels or sentences (CMU index descriptions, KIT-ML sentences). The dataset builder stores
a clip's actions in its meta (``labels["actions"]``, the main action first); ``known_actions``
counts them over a built dataset, so a model can tell users what it knows.

``find_actions(text)`` returns the actions a text names, in the order they appear; where two
patterns overlap, the longer match wins ("jumping jacks" over "jump", "spin kick" over "kick").
"""
from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

from ..errors import ShapeMoveError
from .built_meta import clip_meta, iter_meta


@dataclass(frozen=True)
class Action:
    name: str
    phrases: tuple      # verb phrases the captions use, third person present ("walks forward")
    patterns: tuple     # regexes (lower-case text) that recognise the action
    group: str          # locomotion | acrobatics | floor | exercise | gesture | combat | sport | dance


# everyday words for the actions, beyond the labels and the caption generator's phrases ("ambles",
# "tiptoes", "hurls", "on all fours"): what people type; a longer match wins over a shorter one it
# overlaps ("creeps along on all fours" is a crawl, not a sneak)
_EVERYDAY = {
    "walk": (
        r"\bambl(e|es|ing)\b", r"\bsaunter", r"\btrudg", r"\bwander", r"\bon foot\b",
        r"\bone foot after the other\b", r"\bpac(e|es|ing) (ahead|forward|along|onward|on)\b", r"\bstagger",
        r"\bdrag\w* (his|her|their|your) feet\b", r"\btoddl(e|es|ed|ing)\b", r"\bstrut", r"\bswagger", r"\bplod", r"\bmosey",
        r"\bmeander", r"\bpromenad", r"\btramp(s|ing|ed)?\b", r"\bwaddl", r"\btotter", r"\bhik(e|es|ing)\b",
        r"\bshuffl\w* (forward|along|ahead|slowly|down|across|through|toward|towards)\b",
        r"\bhurr(y|ies|ied|ying) (down|ahead|along|across|off|away|forward|to|after|home)\b(?!.*\b(run|jog|trot|sprint|dash))",
        r"(?<!side-)(?<!side )\bstep(s|ping|ped)? (forward|ahead|along)\b",
        r"\btak(e|es|ing) (a |some |a few |a couple of |two |three |four |several |small |little |tiny |slow )*steps?\b"
        r"(?! (to the side|sideways|back|backwards?|to (the|his|her|their|your) (left|right))\b)",
    ),
    "walk backward": (r"\bin reverse\b", r"\bbacks? away\b", r"\bretreat", r"\bback(s|ing|ed) up\b",
                      r"\bstep\w* backwards?\b(?! and (forth|forwards?)\b)",
                      r"\bstep(s|ping|ped)? back\b(?! (and (forth|forwards?)|to|into|in|inside|onto|from)\b)",
                      r"\bbackpedal",),
    "sidestep": (r"\blike a crab\b", r"\blaterally\b", r"\bshuffl\w* (to the )?(sideways|side|left|right)\b",
                 r"\bshuffl\w* to (his|her|their|your|the) (left|right|side)\b", r"\bstraf(e|es|ing)\b",
                 r"\bside shuffl", r"\bstep(s|ping|ped)? (over |across )?to (the|his|her|their|your) (left|right)\b",
                 r"\bslid(e|es|ing) (over |across )?to (the|his|her|their|your) (left|right|side)\b",),
    "turn": (r"\babout[- ]face\b", r"\bswivel", r"\bpivot(s|ed|ing)?\b", r"\bfac(e|es|ing) the other way\b",),
    "walk in a circle": (
        r"\bcircular (path|route|track)\b", r"\bround and round\b", r"\bcircles? the room\b", r"\bin a (\w+ )?loop\b",
        r"\bin a (big|large|small|little|wide|tight|full) circle\b",
        r"\b(walk|run|jog|stroll|march)\w* a (\w+ )?loop\b", r"\bloop(s|ing)? (a)?round\b",
        r"\bcircl(e|es|ed|ing) (a)?round\b",
        r"\bcircl(es|ed|ing) (around )?(the|a) (room|yard|field|track|park|block|hall|square|pond|fountain|tree|table|"
        r"garden|courtyard|lobby|stage|ring|arena)\b",
    ),
    "walk in a figure eight": (r"\b(eight|infinity)[- ]shaped\b", r"\binfinity (sign|shape|path)\b",
                               r"\b8[- ]?(shape|shaped|pattern|path|route)\b",),
    "run": (r"\brac(e|es|ing) (down|ahead|along|across|around|off|away|forward|to)\b", r"\bscurr", r"\bscamper",
            r"\brush(es|ing|ed)? (down|ahead|along|across|off|away|forward|to)\b",),
    "jog": (r"\btrot(s|ting|ted)?\b", r"\bjoggers?\b",),
    "sprint": (
        r"\bbolt(s|ed|ing)? (ahead|off|away|forward)\b", r"\b(at )?(top|full) speed\b",
        r"\bas fast as (possible|\w+ can)\b", r"\brun\w* (\w+ ){0,2}(at )?(top|full) speed\b", r"\bfull tilt\b", r"\bhell for leather\b",
    ),
    "march": (r"\bparad(e|es|ing)\b", r"\bgoose[- ]?step",),
    "limp": (r"\bhobbl", r"\b(hurt|injured|sore|wounded|sprained|twisted|broken|lame) (right |left )?(leg|ankle|knee|foot)\b",),
    "sneak": (r"\btiptoe", r"\bslink", r"\bmov(e|es|ing) silently\b", r"\bprowl", r"\bstalk(s|ing|ed)?\b",
              r"\bpussyfoot",),
    "zombie walk": (r"\bshambl", r"\blurch", r"\bundead\b", r"\bwalking (corpse|dead)\b", r"\bcorpse", r"\bghoul",),
    "crawl": (
        r"\bon all fours\b", r"\bcreep\w* (\w+ )?on all fours\b", r"\bon (his |her |their |your )?hands and knees\b",
    ),
    "jump": (r"\bspring(s|ing)? (straight |right )?(up|upward|into the air)\b",
             r"\bbounc\w* (straight )?up off the (ground|floor)\b", r"\bvault(s|ed|ing)?\b", r"\bskip\w* (a |the )?rope\b",),
    "jump forward": (r"\b(broad|standing long) jumps?\b", r"\bleap\w* as far\b", r"\bleap\w* (forward|ahead|across)\b",
                     r"\bjump\w* across\b", r"\b(jump|leap)\w* over (a|an|the|some|his|her|their)\b",),
    "spin jump": (r"\b(jump|leap)\w* (up )?and (twirl|spin|turn|rotat)\w*",
                  r"\b(jump|leap)\w*( \w+){0,3} (a |an )?(full|360|180|half)[- ]?(degree )?(turn|spin|rotation|twist)\b",),
    "hop": (r"\bskip\w* (along )?on one (leg|foot)\b", r"\bbounc\w* on (both|two) feet\b",
            r"\bbounc(e|es|ed|ing) (up and down|in place|on the spot)\b",
            r"\bskip(s|ping|ped)?\b(?!\s+(rope|over|the|a|an)\b)",),
    "jumping jacks": (r"\bstar[- ]?jumps?\b",),
    "backflip": (r"\bsomersault\w* backwards?\b", r"\bback tuck\b", r"\bflip\w* over backwards?\b",
                 r"\bback somersault", r"\bback handspring",),
    "sideflip": (r"\bflip\w* over sideways\b", r"\baerial twist to the side\b",),
    "cartwheel": (r"\bwheel\w* sideways\b",),
    "roll": (r"\bsomersault\w*\b(?! backwards?)", r"\btumbl",),
    "get up": (
        r"\bris(e|es|ing) from the (floor|ground)\b", r"\bonto (his|her|their|your) feet\b", r"\bcome to standing\b",
        r"\bto a standing position\b", r"\bris(e|es|ing) from (lying|sitting|a lying position)( down)?\b", r"\b\w+ (back )?(up )?(on)?to (his|her|their|your|one's|its) feet\b",
    ),
    "lie down": (r"\breclin", r"\b(lay|lays|lie|lies|lying) flat\b", r"\bstretch\w* out flat\b", r"\bprone\b",
                 r"\bsupine\b",),
    "sit": (
        r"\btak(e|es|ing) a seat\b", r"\bplop\w* down\b", r"\blower\w* (yourself|himself|herself|themselves) onto\b",
        r"\bperch", r"\bseat(s|ed)? (himself|herself|themselves|yourself)\b",
        r"\b(settl|sink|sank|sunk)\w* (down )?(in|into|on|onto) (a|the|his|her|their|your) (chair|couch|sofa|armchair|bench|seat|stool)\b",
    ),
    "climb": (r"\bscal(e|es|ing) (a|the) (\w+ )?(ladder|wall|rope|cliff|rock|fence)\b", r"\bladder\b",
              r"\bclamber\w* (up|over|onto)\b", r"\bscrambl\w* up\b", r"\b(rock|climbing) wall\b",),
    "squat": (r"\bknee bends?\b", r"\bhunker", r"\bcrouch(es)?\b(?! (over|forward)\b)", r"\bcrouch\w* down\b", r"\blower\w* the hips\b", r"\bsink\w* down by bending\b",
              r"\bduck(s|ed|ing)? (down|under|low|behind)\b",),
    "bend over": (r"\bfold\w* forward\b", r"\btouch\w* (his|her|their|your|the) toes\b", r"\bstoop(s|ed|ing)? (over|down)\b",
                  r"\blean\w* down\b", r"\blean\w* (over|forward) (at|from) the (waist|hips)\b",
                  r"\bfold\w* (over |down )?at the (waist|hips)\b",),
    "pick up": (
        r"\blift\w* (a|an|the) \w+ (off|from) (the )?(floor|ground)\b",
        r"\bcollect\w* (an? |the )?\w+ (lying )?on the (floor|ground)\b",
        r"\blift\w* (a|an|the|some|his|her|their) (heavy |big |small |large |light )?(box|bag|crate|package|parcel|"
        r"suitcase|bucket|weight|barbell|dumbbell|rock|stone)s?\b",
        r"\b(grab|retriev|gather)\w* (\w+ ){0,3}(from|off) the (floor|ground)\b",
    ),
    "put down": (r"\bset\w* (a|an|the) \w+ down\b", r"\b(plac|set|drop|put)\w* (\w+ ){1,3}(on|onto|to) the (floor|ground)\b",
                 r"\blower\w* (?!(?:him|her|them|your|one|it)sel)(\w+ ){1,3}(to|onto) the (floor|ground)\b",),
    "reach up": (r"\bextend\w* an arm overhead\b", r"\breach\w* overhead\b", r"\bstretch\w* up( on (his |her |their |your )?tip-?toes?)?\b",),
    "stretch": (r"\bflexibility\b", r"\blengthen",),
    "side twist": (r"\b(torso|trunk) rotations?\b", r"\brotat\w* (the|his|her|their|your|one's) (torso|trunk|upper body)\b",),
    "elbow to knee": (r"\bcross crunch", r"\belbows? (meeting|touching) (the )?opposite knees?\b",
                      r"\b(standing|bicycle|oblique) crunch", r"\belbows? (\w+ ){0,2}to (\w+ ){0,2}knees?\b",),
    "arm circles": (r"\bwindmill", r"\bcircular swings? of the arms\b",
                    r"\b(swing|swung|mov|rotat|whirl|wav|twirl)\w* (his|her|their|the|both|your|one's)( \w+)? arms "
                    r"(around )?in (\w+ )?circles\b",
                    r"\b(roll|spin|swing|swung|rotat|whirl|twirl|circl)\w* (his|her|their|the|both|your|one's)( \w+)? arms "
                    r"(a?round|in (\w+ )?(loops|circles))\b",),
    "balance": (r"\b(hold|keep|stay)\w* (\w+ ){0,2}(steady|still|balanced) on one (foot|leg)\b",
                r"\bflamingo\b", r"\bsingle[- ]leg stance\b", r"\bstand\w* on one (foot|leg)\b", r"\bteeter",
                r"\btightrope",),
    "wave": (
        r"\bsignals? hello\b", r"\bsay(s)? hi\b", r"\bflaps? a hand\b", r"\bwaggl\w* (a|one|his|her|their|the) (\w+ )?hand\b",
        r"\bgreet\w* (\w+ ){0,3}with a (\w+ )?(hand|arm)\b", r"(?<!to )\bgreet(s|ed|ing)?\b", r"\bsays? hello\b",
    ),
    "wave goodbye": (r"\bfarewell\b", r"\bsee[- ]you[- ]later\b",),
    "guide": (r"\bshow\w* (\w+ ){0,3}the way\b", r"\bpoint\w* the way\b", r"\busher", r"\bdirect\w* traffic\b",
              r"\bthis way\b", r"\bpoint\w* out the (exits?|way|doors?)\b",
              r"\bdirect(s|ed|ing)? (the |a |an )?(visitors?|guests?|people|crowd|passengers?|customers?|tourists?)\b",
              r"\bgestur\w* (toward|towards|to) (the |a )?(doors?|exits?|entrance|way)\b",),
    "hang": (r"\bdangl\w* from\b", r"\bmonkey bars\b",),
    "wash": (r"\bscrub", r"\brins(e|es|ing)\b", r"\blather", r"\bbath(e|es|ing)\b",),
    "raise hand": (r"\bhold\w* (one|an|both|a) arms? (straight )?up\b", r"\barms? (straight )?up in the air\b",
                   r"\blift\w* (one|a|both|his|her|their|the) (\w+ )?(hands?|arms?)\b",
                   r"\b(arms?|hands?|fists?) (thrust|shot|flung|stretched|reaching) (straight )?((up|upward|skyward)"
                   r"( (in|into) the air)?|overhead|into the air)\b",
                   r"\b(arms?|hands?) (held )?(raised|lifted|aloft|up high)\b",
                   r"\b(with|keep|keeps|keeping|hold|holds|holding) (\w+ ){0,2}(arms?|hands?) (held )?(up|raised|high|aloft|above|"
                   r"overhead|in the air)\b",
                   r"\bput\w* up (a|one|his|her|their|your|both) (hand|hands|arm|arms)\b", r"\bsurrender",),
    "bow": (r"\bbend\w* (\w+ )?at the waist\b", r"\bcurts(e)?y",),
    "beckon": (r"\bmotion\w* for (\w+ ){0,3}to come\b", r"\bcome closer\b", r"\bgestur\w* for (\w+ ){0,3}to come\b",
               r"\bmotion\w* (\w+ ){0,2}(over|closer)\b", r"\bcome here\b", r"\bwav\w* (\w+ )?over\b", r"\bsummon",
               r"\bcall\w* (\w+ ){0,2}over\b", r"\bcurl\w* (a|his|her|their|your|one|one's) (index )?finger\b",),
    "punch": (r"\bone-two\b", r"\bshadow ?box", r"\buppercut", r"\bthrow\w* (\w+ ){0,2}(punch(es)?|jabs?|hooks?|uppercuts?)\b",
              r"\b(left|right) hooks?\b", r"\bhaymaker", r"\bpummel", r"\bhit\w* (\w+ ){0,2}with (a|his|her|their|the) (\w+ )?fists?\b",),
    "kick": (r"\blash\w* out with (a|the|one|his|her) (foot|leg)\b", r"\bboot(s)? \w+ away\b",
             r"\bboot(s|ing|ed)? (something|someone|it|him|her|them|the|a)\b",),
    "spin kick": (r"\bwhirl\w* around and kicks?\b", r"\bspinning (back |heel |hook )kick", r"\btornado kick",),
    "slash": (r"\bblade\b", r"\b\w*sword\b", r"\bswing\w* (a |an |the )?\w*sword\b", r"\bkatana", r"\bmachete",
              r"\bsab(re|er)\b", r"\bcutlass", r"\bslic(e|es|ing)\b", r"\bhack\w* at\b",),
    "kick ball": (r"\bstrik\w* the ball\b", r"\bpunt", r"\bkick\w* (a |the )?football", r"\bclear\w* the ball\b",
                  r"\bnudg\w* (a|the) ball\b",
                  r"\bboot\w* (a |the )?(foot|soccer )?ball\b",),
    "throw": (r"\bhurl", r"\btoss", r"\bpitch\w* (a|the) (base)?ball\b", r"\bfling", r"\blob(s|bed|bing)?\b",
              r"\b(throw\w*|threw) (a |the )?(\w+ )?(base|basket|soft|snow|beach|foot)balls?\b",
              r"\bthrow\w* (a|an|the|his|her|their|some) (\w+ )?(stick|stone|rock|frisbee|javelin|spear|dart|disc|"
              r"discus|bottle|snowball|pillow|bag|box|object|rope|bone)s?\b",
              r"\b(throw\w*|threw) (it|them)\b", r"\bthrow\w* (overhand|underhand|overarm|sidearm)\b",),
    "dribble": (r"\bbounc\w* the (basket)?ball\b",),
    "shoot": (r"\bjump shot\b", r"\bshot at the (hoop|basket)\b", r"\bfree throw", r"\blay-?up\b",),
    "dance": (r"\bgroov", r"\bboogie", r"\bhip[- ]?hop\b", r"\b(mov|sway|bounc|bob|step)\w* to the (beat|music|rhythm)\b", r"\bbust\w* a move\b", r"\bbreak[- ]?danc", r"\btwerk",
              r"\bdisco\b", r"\btango", r"\bwaltz", r"\bsamba\b", r"\bcha[- ]cha", r"\bfoxtrot", r"\bjig\b", r"\bshimmy",
              r"\btap[- ]?danc", r"\bchoreograph",),
    "ballet": (r"\bballerina",),
    "spin": (r"\btwirl", r"\bpivot\w* (a full circle|around)\b",),
    "pose": (r"\bstrik\w* an? [\w -]{0,30}(pose|stance)\b", r"\bpos(ing|ed)\b", r"\bvogue",
             r"\bflex\w* (his|her|their|the|both|your) (biceps?|muscles|arms)\b",),
}


def _a(name, group, phrases, patterns):
    return Action(name, tuple(phrases), tuple(patterns) + _EVERYDAY.get(name, ()), group)


_LIST = [
    # locomotion
    _a("walk", "locomotion", ["walks", "walks forward", "takes a walk"],
       [r"\bwalk(s|ing|ed)?\b", r"\bstroll", r"\bstrid(e|es|ing)\b"]),
    _a("walk backward", "locomotion", ["walks backward", "walks backwards"],
       [r"\bwalk\w*\s+backwards?\b", r"\bbackwards? walk"]),
    _a("sidestep", "locomotion", ["walks sideways", "sidesteps", "steps to the side"],
       [r"\bside[- ]?step(s|ping|ped)?\b", r"\bwalk\w*\s+(to the )?sideways\b", r"\bsideways steps?\b", r"\bwalk\w* sideways",
        r"\bsteps? (to the )?side(ways)?\b"]),
    _a("turn", "locomotion", ["turns around", "turns to face the other way"],
       [r"(?<!\bin )(?<!\btake )(?<!\btakes )(?<!\btaking )\bturn(s|ing|ed)?\b(?! step)"]),
    _a("walk in a circle", "locomotion", ["walks in a circle", "goes around in a circle"],
       [r"\bin (a )?circles?\b", r"\bleft circle\b", r"\bcircle walk"]),
    _a("walk in a figure eight", "locomotion", ["walks in a figure eight", "walks a figure-eight path"],
       [r"figure[- ]?(8|eight)", r"\bdigital ?8\b", r"\bwalk ?8\b", r"\bmummy ?8\b"]),
    _a("run", "locomotion", ["runs", "runs forward"], [r"\brun(s|ning)?\b", r"\bran\b"]),
    _a("jog", "locomotion", ["jogs", "jogs forward", "goes for a jog"], [r"\bjog(s|ging|ged)?\b"]),
    _a("sprint", "locomotion", ["sprints", "dashes forward at full speed"], [r"\bsprint", r"\bdash(es|ing)?\b"]),
    _a("march", "locomotion", ["marches", "marches forward"], [r"\bmarch(es|ing|ed)?\b"]),
    _a("limp", "locomotion", ["limps", "walks with a limp"],
       [r"\blimp", r"\bhurt ?leg", r"\bbad ?leg", r"\bfavou?r\w* (?:(?:one|a|his|her|their|the|one's) )?(?:(?:left|right|bad|hurt|injured) )?leg"]),
    _a("sneak", "locomotion", ["sneaks forward", "walks stealthily", "creeps forward"],
       [r"\bsneak", r"\bstealth", r"\bcreep"]),
    _a("zombie walk", "locomotion", ["walks like a zombie", "shuffles along like a zombie"],
       [r"\bzombie", r"\bmumm(y|ies)\b"]),
    _a("crawl", "floor", ["crawls on hands and knees", "crawls forward"], [r"\bcrawl"]),
    # jumps and acrobatics
    _a("jump", "acrobatics", ["jumps", "jumps up"], [r"\bjump(s|ing|ed)?\b", r"\bleap(s|ing|t)?\b"]),
    _a("jump forward", "acrobatics", ["jumps forward", "does a long jump"],
       [r"\b(forward|far|long) jumps?\b", r"\bjump\w*\s+(\w+ )?forward", r"\bjump\w* far\b", r"\bmakes a far jump"]),
    _a("spin jump", "acrobatics", ["jumps and turns in the air", "does a spinning jump"],
       [r"\bjump ?turn", r"\bjump\w* (up )?(and|while) (turn|spin)", r"\bspinning jump",
        r"\bspin[- ]?jumps?\b", r"^(90|180|270|360)\b(?![- ]?degree)",
        r"\b(90|180|270|360)[- ]?(degrees? )?(\w+ ){0,3}jump"]),
    _a("hop", "acrobatics", ["hops", "hops on both feet"], [r"\bhop(s|ping|ped)?\b"]),
    _a("jumping jacks", "exercise", ["does jumping jacks"], [r"\bjumping[- ]jacks?\b"]),
    _a("backflip", "acrobatics", ["does a backflip", "flips backward"], [r"\bback ?flip", r"\bflip\w* backwards?"]),
    _a("sideflip", "acrobatics", ["does a side flip", "flips sideways"], [r"\bside ?flip", r"\bflip\w* sideways"]),
    _a("cartwheel", "acrobatics", ["does a cartwheel", "turns a cartwheel"], [r"\bcartwheel", r"\bturn\w* a cartwheel"]),
    _a("roll", "floor", ["rolls on the ground", "does a forward roll"],   # not the arms or shoulders rolled
       [r"\broll(s|ing|ed)?\b(?! de| (his|her|their|your|the|both|one's) (\w+ )?(arms?|shoulders?)\b)"]),
    _a("get up", "floor", ["gets up from the ground", "stands up from the floor"],
       [r"\b(get(s|ting)?|got) (back )?up\b", r"\b(stand(s|ing)?|stood) (back )?up\b", r"\bgetup\b"]),
    _a("lie down", "floor", ["lies down on the floor", "lies down"],
       [r"\blie(s)? down", r"\blying down", r"\blays? down",
        r"\blies? (flat|on (his|her|their|the|its|one's|your) (back|side|front|stomach|belly|floor|ground))\b"]),
    _a("sit", "floor", ["sits down", "sits"], [r"\bsit(s|ting)?\b(?![- ]?ups?\b)", r"\bsat\b"]),
    _a("climb", "sport", ["climbs", "climbs up"], [r"\bclimb"]),
    _a("hang", "sport", ["hangs from a bar"], [r"\bhang(s|ing)?\b"]),
    _a("swing", "sport", ["swings from a bar"], [r"\bswing(s|ing)?\b(?! (\w+ )?arms?)"]),
    # exercise
    _a("squat", "exercise", ["does a squat", "squats down"], [r"\bsquat"]),
    _a("bend over", "exercise", ["bends over", "bends down"], [r"\bbend(s|ing)? (over|down)\b", r"\bbent over\b"]),
    _a("pick up", "exercise", ["picks something up from the floor"],
       [r"\bpick\w* (\w+ ){0,3}up\b", r"\bscoop"]),   # "picks the heavy box up"
    _a("put down", "exercise", ["puts something down on the floor"],
       [r"\bput\w* (\w+ ){0,3}down\b", r"\bdeposit"]),   # "puts a box down"
    _a("reach up", "exercise", ["reaches up high", "reaches up and grabs something"],
       [r"\breach(es|ing)? (up|for|high)", r"\bgrab"]),
    _a("stretch", "exercise", ["stretches", "does stretches"], [r"\bstretch(es|ing|ed)?\b"]),
    _a("side twist", "exercise", ["does side twists", "twists the upper body from side to side"],
       [r"\bside twists?\b", r"\btwist(?!\w* (?:(?:an|a|his|her|their|the|one's|my|your) )?(?:ankle|knee|foot|wrist))"]),
    _a("elbow to knee", "exercise", ["touches each elbow to the opposite knee"],
       [r"\belbow\w* to (the )?(opposite )?knees?"]),
    _a("arm circles", "exercise", ["rotates both arms", "makes circles with the arms"],
       [r"\brotat\w* (both )?arms", r"\barm circles", r"\bcircl\w* (both |the |his |her |their |your )?arms", r"\bcircles with the arms"]),
    _a("balance", "exercise", ["balances on one leg"], [r"\bbalanc"]),
    # gestures
    _a("wave", "gesture", ["waves", "waves a hand"], [r"\bwav(e|es|ed|ing)\b"]),
    _a("wave goodbye", "gesture", ["waves goodbye"], [r"\bwav\w* (good)?-?bye", r"\bbye ?bye\b", r"\bbye\b"]),
    _a("raise hand", "gesture", ["raises a hand", "raises a hand up"],
       [r"\brais\w* (\w+ ){0,2}(hand|hands|arm|arms)\b", r"\blift\w* (\w+ )?arms?\b", r"\bhands? (up|in the air)",
        r"\braise-up"]),
    _a("bow", "gesture", ["bows", "takes a bow"], [r"\bbow(s|ing|ed)?\b"]),
    _a("beckon", "gesture", ["beckons someone to come over", "calls someone over with a hand"],
       [r"\bbeckon", r"\bcall\w* (someone|somebody)"]),
    _a("guide", "gesture", ["guides someone with an open hand", "shows the way with a hand"],
       [r"\bguid(e|es|ing)\b", r"\bshows? the way"]),
    # combat
    _a("punch", "combat", ["throws punches", "punches"], [r"\bpunch", r"\bstrike\b", r"\bbox(es|ing)\b", r"\bjab"]),
    _a("kick", "combat", ["kicks", "kicks with one leg"], [r"\bkick(s|ing|ed)?\b"]),
    _a("spin kick", "combat", ["does a spinning kick", "does a spin kick"],
       [r"\bspin ?kick", r"\bspinning kick", r"\broundhouse"]),
    _a("slash", "combat", ["slashes with a sword", "swings a sword"], [r"\bslash", r"\bsword", r"\bswing\w* (a |the )?sword"]),
    # sport
    _a("kick ball", "sport", ["kicks a ball"], [r"\bkick\w* (a |the )?(soccer )?ball", r"\bsoccer"]),
    _a("throw", "sport", ["throws a ball"], [r"\b(throw\w*|threw) (a |the )?(\w+ )?ball", r"\bthrowbasketball"]),
    _a("dribble", "sport", ["dribbles a basketball"], [r"\bdribbl"]),
    _a("shoot", "sport", ["shoots a basketball"],
       [r"\bshoot(s|ing)?\b(?! up\b| (his|her|their|your|a|one|the|both)( left| right)? (hand|arm|fist)s?\b)"]),
    # dance
    _a("dance", "dance", ["dances", "does a dance"],
       [r"\bdanc(e|es|ed|ing|er)\b", r"\bsalsa", r"\blambada", r"\blindy ?hop"]),
    _a("ballet", "dance", ["does ballet moves", "dances ballet"],
       [r"\bballet", r"\barabesque", r"\bjetes?\b", r"\bglissade", r"\bplie\b", r"\bpirouettes?\b"]),
    _a("spin", "dance", ["spins around", "turns on the spot"],   # not the arms spun round
       [r"\bspin(s|ning)?\b(?! (his|her|their|your|the|both|one's) (\w+ )?arms?\b)", r"\bspun\b", r"\bwhirl",
        r"\bpirouettes?\b", r"\bturns? on the spot"]),
    _a("pose", "dance", ["holds a pose", "strikes a pose"], [r"\bposes?\b", r"\byoga"]),
    _a("wash", "gesture", ["washes", "takes a shower"], [r"\bwash", r"\bshower"]),
]

ACTIONS: dict[str, Action] = {a.name: a for a in _LIST}
_COMPILED = [(a.name, re.compile(p)) for a in _LIST for p in a.patterns]


def action(name: str) -> Action:
    try:
        return ACTIONS[name]
    except KeyError:
        raise ShapeMoveError(f"unknown action {name!r}; known: {', '.join(ACTIONS)}") from None


# a specific action -> the generic ones its words also name ("walks in a circle": walk)
GENERIC_OF = {"walk in a figure eight": ("walk",), "walk in a circle": ("walk",), "zombie walk": ("walk",),
              "limp": ("walk",), "sneak": ("walk",), "walk backward": ("walk",), "jump forward": ("jump",),
              "spin jump": ("jump", "spin"), "kick ball": ("kick",), "spin kick": ("kick", "spin"),
              "ballet": ("dance",), "wave goodbye": ("wave",), "cartwheel": ("turn",), "slash": ("swing",),
              "hop": ("jump",), "shoot": ("throw",)}   # a shot at the basket is thrown


# actions done over and over by their nature: a take of one repetition plays on as a loop of it
# (``generation.take_loop.looped_repetition``); a kick or a throw done once is held instead (a
# gait's one-cycle take too: docs/design-notes.md)
REPEATED = frozenset({"arm circles", "jumping jacks", "dribble", "elbow to knee", "side twist", "hop"})
MOVES_ON = frozenset({"dribble", "hop"})   # of those, the ones that may go somewhere as they repeat


def action_verb(action: str) -> str:
    """How the vocabulary says an action's verb ("marches", "hops"), for the notes a motion gives;
    the name itself for an action the vocabulary lacks."""
    return ACTIONS[action].phrases[0].split()[0] if action in ACTIONS else action


def specific(acts: list[str]) -> list[str]:
    """Drop the generic actions of the specific ones also present (["walk", "limp"] -> ["limp"])."""
    drop = {g for a in acts for g in GENERIC_OF.get(a, ())}
    return [a for a in acts if a not in drop]


# words an action's pattern finds that name a person by what they do: the action only when the text
# names no other ("a dancer performs": dance; "a dancer spins": a spin)
DOER_WORDS = frozenset({"dancer", "dancers", "climber", "climbers", "sprinter", "sprinters", "crawler", "crawlers"})
# words an action's pattern finds that name no action ("a man in sneakers walks", "a creepy figure waves")
NOT_ACTION_WORDS = frozenset({"sneaker", "sneakers", "creepy", "creepily"})


def _word_at(text: str, i: int) -> str:
    """The whole word of ``text`` holding position ``i``."""
    before = re.search(r"[a-z'-]*$", text[:i]).group(0)
    return before + re.match(r"[a-z'-]*", text[i:]).group(0)


def action_spans(text: str) -> list[tuple[int, int, str]]:
    """(start, end, action) of every action named in ``split_words(text)``, in order of appearance;
    where two patterns overlap, the longer match wins ("jumping jacks" over "jump"). A match in a
    word of ``NOT_ACTION_WORDS`` names nothing, one in a word of ``DOER_WORDS`` only when nothing
    else is named."""
    text = split_words(text)
    hits = []  # (start, -length, name, end)
    for name, rx in _COMPILED:
        for m in rx.finditer(text):
            hits.append((m.start(), -(m.end() - m.start()), name, m.end()))
    taken: list[tuple[int, int, str]] = []
    for start, neg, name, end in sorted(hits, key=lambda h: (h[1], h[0])):  # longest first
        if not any(start < e and end > s for s, e, _ in taken):
            taken.append((start, end, name))
    taken = [sp for sp in taken if _word_at(text, sp[0]) not in NOT_ACTION_WORDS]
    doing = [sp for sp in taken if _word_at(text, sp[0]) not in DOER_WORDS]
    return sorted(doing or taken)


def find_actions(text: str) -> list[str]:
    """The canonical actions a text names, in order of appearance (longer overlapping match wins),
    except that a specific action comes before the generic one it implies ("walks with a limp":
    limp, walk)."""
    out: list[str] = []
    for _, _, name in action_spans(text):
        if name not in out:
            out.append(name)
    first = specific(out)
    return first + [a for a in out if a not in first]


def split_words(text: str) -> str:
    """Lower-case text with camelCase and digits split off ('WalkDigital8' -> 'walk digital 8')."""
    text = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", str(text))
    text = re.sub(r"(?<=[A-Za-z])(?=8\b)", " ", text)
    return re.sub(r"[_]+", " ", text).lower()


# Source labels with a known meaning (the first action is the clip's main one)
BANDAI_ACTIONS = {
    "walk": ["walk"], "run": ["run"], "dash": ["sprint"], "walk-back": ["walk backward"],
    "walk-left": ["sidestep"], "walk-right": ["sidestep"], "walk-turn-left": ["walk", "turn"],
    "walk-turn-right": ["walk", "turn"], "bow": ["bow"], "bye": ["wave goodbye"], "byebye": ["wave goodbye"],
    "guide": ["guide"], "respond": ["raise hand"], "call": ["beckon"], "punch": ["punch"], "kick": ["kick"],
    "slash": ["slash"], "dance-long": ["dance"], "dance-short": ["dance"], "wave-both-hands": ["wave"],
    "wave-left-hand": ["wave"], "wave-right-hand": ["wave"], "raise-up-both-hands": ["raise hand"],
    "raise-up-left-hand": ["raise hand"], "raise-up-right-hand": ["raise hand"],
}
HDM05_ACTIONS = {
    "squat": ["squat"], "hopBothLegs": ["hop"], "depositFloorR": ["put down", "bend over"], "kickLFront": ["kick"],
    "grabHighR": ["reach up"], "elbowToKnee": ["elbow to knee"], "lieDownFloor": ["lie down"],
    "rotateArmsBothBackward": ["arm circles"], "jogLeftCircle": ["jog", "walk in a circle"], "sneak": ["sneak"],
    "throwBasketball": ["throw"],
}
DEEPMIMIC_ACTIONS = {
    "backflip": ["backflip"], "sideflip": ["sideflip"], "cartwheel": ["cartwheel"], "crawl": ["crawl"],
    "getup_faceup": ["get up"], "getup_facedown": ["get up"], "roll": ["roll"], "spinkick": ["spin kick"],
    "dance_a": ["dance"], "dance_b": ["dance"], "dance_spin": ["dance", "spin"], "zombie_walk": ["zombie walk"],
    "long_zombie": ["zombie walk"], "stealthy_walk": ["sneak"], "jog": ["jog"], "run": ["run"], "walk": ["walk"],
    "long_walk": ["walk"], "jump": ["jump forward", "jump"], "kick": ["kick"], "punch": ["punch"], "spin": ["spin"],
}


def _prefix_lookup(table: dict, key: str) -> list[str]:
    for k in sorted(table, key=len, reverse=True):
        if key.startswith(k):
            return list(table[k])
    return []


def clip_actions(dataset: str, labels: dict, captions: list[str]) -> list[str]:
    """A clip's actions, main one first: from its source label where the label is known, else
    (CMU, user folders) from its description and captions."""
    if dataset == "bandai":
        return list(BANDAI_ACTIONS.get(labels.get("content", ""), [])) or _from_text(labels, captions)
    if dataset == "hdm05":
        return _prefix_lookup(HDM05_ACTIONS, labels.get("class", "")) or _from_text(labels, captions)
    if dataset == "deepmimic":
        return _prefix_lookup(DEEPMIMIC_ACTIONS, labels.get("motion", "")) or _from_text(labels, captions)
    return _from_text(labels, captions)


def _from_text(labels: dict, captions: list[str]) -> list[str]:
    desc = labels.get("description", "")
    if " - " in desc:  # "dance - pirouette": the scene names an action too
        scene, rest = desc.split(" - ", 1)
        out = find_actions(scene)
        out += [a for a in find_actions(rest) if a not in out]
    else:
        out = find_actions(desc)
    for c in captions:
        out += [a for a in find_actions(c) if a not in out]
    return out


def known_actions(data_dir, split: str | None = None) -> list[tuple[str, int]]:
    """(action, number of clips) over a built dataset's ``meta.jsonl`` (or ``meta/*.json``, read by
    ``built_meta.iter_meta``), most frequent first; ``split`` restricts to one split. Composed and
    augmented clips count too."""
    counts: Counter = Counter()
    for m in iter_meta(data_dir):
        if split is not None and m.get("split") != split:
            continue
        labels = m.get("labels")
        acts = labels.get("actions") if isinstance(labels, dict) else None
        if isinstance(acts, list):
            counts.update({a for a in acts if isinstance(a, str)})  # one count per clip
    return sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))


def stored_labels(data_dir, clip_id: str) -> dict:
    """The ``labels`` of a built clip's ``meta/{clip_id}.json`` ({} when it has none; a note when it is
    too large or unreadable, ``built_meta.clip_meta``):
    ``actions`` (main first) and, for clips that hold several actions in turn, ``sequence``."""
    labels = clip_meta(data_dir, clip_id).get("labels")
    return labels if isinstance(labels, dict) else {}
