"""Natural-language captions from the labels the mocap archives carry, with augmentation.

Bandai: content + style label per clip; HDM05: an action class in the file name; CMU: KIT-ML
sentences where present plus sentences from the CMU index description (its actions, styles and
details); DeepMimic: the motion's file name. Each clip gets several varied sentences: synonym verb
phrases (``actions.ACTIONS`` and the per-source tables here), subjects ("a person", "someone",
"a woman", ...), sentence shapes ("... walks.", "... is walking.", "Happily, ... walks.") and
styles as adverbs. Choices are deterministic per clip id (a rebuild writes the same text). The
first caption of a clip is always its plainest sentence (search results show it).
"""
from __future__ import annotations

import hashlib
import re

from .actions import ACTIONS, find_actions, specific, split_words

N_CAPTIONS = 6

# Bandai content labels -> verb phrases (third person, present tense); the first is the plainest
BANDAI_CONTENT = {
    "walk": ["walks forward", "walks", "walks straight ahead"],
    "run": ["runs forward", "runs", "runs straight ahead"],
    "dash": ["dashes forward at full speed", "sprints forward", "sprints"],
    "walk-back": ["walks backward", "walks backwards", "steps backward"],
    "walk-left": ["walks sideways to the left", "sidesteps to the left", "steps sideways to the left"],
    "walk-right": ["walks sideways to the right", "sidesteps to the right", "steps sideways to the right"],
    "walk-turn-left": ["walks and turns to the left", "walks forward and turns left", "walks, turning to the left"],
    "walk-turn-right": ["walks and turns to the right", "walks forward and turns right",
                        "walks, turning to the right"],
    "bow": ["bows", "takes a bow", "bows politely"],
    "bye": ["waves goodbye with one hand", "waves goodbye", "waves one hand to say goodbye"],
    "byebye": ["waves goodbye with both hands", "waves goodbye", "waves both hands to say goodbye"],
    "guide": ["guides someone with an open-hand gesture", "shows the way with an open hand",
              "guides someone with a hand"],
    "respond": ["raises a hand to respond", "raises a hand in reply", "responds by raising a hand"],
    "call": ["beckons someone to come over", "calls someone over with a hand", "beckons someone"],
    "punch": ["throws punches", "punches", "throws a few punches"],
    "kick": ["kicks", "kicks with one leg", "does a kick"],
    "slash": ["slashes with a sword", "swings a sword", "slashes"],
    "dance-long": ["dances", "does a dance", "dances for a while"],
    "dance-short": ["does a short dance", "dances briefly", "dances"],
    "wave-both-hands": ["waves with both hands", "waves both hands", "waves"],
    "wave-left-hand": ["waves with the left hand", "waves the left hand", "waves a hand, the left one"],
    "wave-right-hand": ["waves with the right hand", "waves the right hand", "waves a hand, the right one"],
    "raise-up-both-hands": ["raises both hands", "raises both hands up", "raises both arms"],
    "raise-up-left-hand": ["raises the left hand", "raises the left hand up", "raises the left arm"],
    "raise-up-right-hand": ["raises the right hand", "raises the right hand up", "raises the right arm"],
}

# Bandai style labels -> (subject noun phrase, adverbs / manner phrases)
BANDAI_STYLE = {
    "normal": ("a person", []),
    "happy": ("a happy person", ["happily", "cheerfully"]),
    "sad": ("a sad person", ["sadly", "gloomily"]),
    "angry": ("an angry person", ["angrily", "furiously"]),
    "proud": ("a proud person", ["proudly", "with pride"]),
    "not-confident": ("an unconfident person", ["timidly", "without confidence"]),
    "masculinity": ("a person", ["in a masculine manner", "in a manly way"]),
    "masculine": ("a person", ["in a masculine manner", "in a manly way"]),
    "feminine": ("a person", ["in a feminine manner", "in a feminine way"]),
    "childish": ("a childlike person", ["in a childish way", "childishly"]),
    "youthful": ("a young person", ["energetically, with youthful vigour", "youthfully"]),
    "old": ("an old person", ["slowly, like an old person", "stiffly, like an old person"]),
    "elderly": ("an elderly person", ["slowly, like an elderly person", "stiffly, like an elderly person"]),
    "tired": ("a tired person", ["wearily", "tiredly"]),
    "exhausted": ("an exhausted person", ["with exhaustion", "wearily, exhausted"]),
    "active": ("an energetic person", ["actively", "energetically"]),
    "musical": ("a person", ["rhythmically, like in a musical", "rhythmically"]),
    "giant": ("a person", ["with heavy steps, like a giant", "heavily, like a giant"]),
    "chimpira": ("a person", ["with a swagger, like a street thug", "with a swagger"]),
}

HDM05_CLASSES = {
    "squat": ["does a squat", "squats down and stands up again", "squats"],
    "hopBothLegs": ["hops on both legs", "hops with both feet", "hops"],
    "depositFloorR": ["bends down and puts something on the floor with the right hand",
                      "puts something down on the floor with the right hand", "bends down to put something down"],
    "kickLFront": ["kicks forward with the left leg", "kicks with the left foot", "does a front kick with the left leg"],
    "grabHighR": ["reaches up high and grabs something with the right hand",
                  "grabs something up high with the right hand", "reaches up with the right hand"],
    "elbowToKnee": ["touches each elbow to the opposite knee", "brings the elbows to the opposite knees",
                    "does elbow-to-knee crunches"],
    "lieDownFloor": ["lies down on the floor", "lies down", "gets down and lies on the floor"],
    "rotateArmsBothBackward": ["rotates both arms backward", "circles both arms backward", "does backward arm circles"],
    "jogLeftCircle": ["jogs in a circle to the left", "jogs around in a circle", "jogs in a circle"],
    "sneak": ["sneaks forward", "sneaks", "walks stealthily"],
    "throwBasketball": ["throws a basketball", "throws a ball", "throws a basketball with both hands"],
}

# DeepMimic motion names (file name minus "humanoid3d_") -> verb phrases
DEEPMIMIC_MOTIONS = {
    "backflip": ["does a backflip", "flips backward", "does a back somersault"],
    "sideflip": ["does a side flip", "flips sideways", "does a sideways somersault"],
    "cartwheel": ["does a cartwheel", "turns a cartwheel", "does a cartwheel to the side"],
    "crawl": ["crawls on hands and knees", "crawls forward", "crawls"],
    "getup_faceup": ["gets up from lying on the back", "gets up off the floor", "stands up from the floor"],
    "getup_facedown": ["gets up from lying face down", "gets up off the floor", "stands up from the floor"],
    "roll": ["does a forward roll", "rolls forward on the ground", "rolls on the ground"],
    "spinkick": ["does a spinning kick", "does a spin kick", "spins and kicks"],
    "dance_a": ["dances", "does a dance", "dances in place"],
    "dance_b": ["dances", "does a dance", "dances energetically"],
    "dance_spin": ["dances and spins around", "spins while dancing", "does a dance spin"],
    "zombie_walk": ["walks like a zombie", "shuffles along like a zombie", "walks with arms out like a zombie"],
    "long_zombie": ["walks like a zombie", "shuffles along like a zombie", "walks around like a zombie"],
    "stealthy_walk": ["sneaks forward", "walks stealthily", "creeps forward"],
    "jog": ["jogs", "jogs forward", "goes for a jog"],
    "run": ["runs", "runs forward", "runs fast"],
    "walk": ["walks forward", "walks", "walks straight ahead"],
    "long_walk": ["walks around", "walks, changing direction", "walks forward and turns"],
    "jump": ["jumps forward", "does a long jump", "jumps forward with both feet"],
    "kick": ["kicks", "does a kick", "kicks forward"],
    "punch": ["throws punches", "punches", "throws a few punches"],
    "spin": ["spins around", "turns on the spot", "spins"],
}

# CMU index style words (mostly subject 105's styled walks) -> adverbs; longer keys first when matching
CMU_STYLES = {
    "slow": "slowly", "lavish": "extravagantly", "too cool": "with an exaggerated cool swagger",
    "cool": "coolly, with a swagger", "sad": "sadly", "depressed": "dejectedly", "clumsy": "clumsily",
    "quick": "quickly", "careful": "carefully", "shy": "shyly", "achey": "stiffly, as if aching",
    "casual quick": "quickly and casually", "hurt leg": "with a hurt leg", "drag bad leg": "dragging a bad leg",
    "hurt stomach": "bent forward, as if with a hurt stomach", "ghetto": "with a swagger",
    "sexy": "seductively", "scared": "fearfully", "macho": "in a macho way",
    "traffic": "cautiously, as if through traffic", "brisk": "briskly", "exaggerated stride": "with exaggerated strides",
    "looking around": "looking around", "uneven terrain": "over uneven terrain",
}

SUBJECTS = ["a person", "someone", "a man", "a woman", "the person", "a human"]

# irregular gerunds and doubled consonants for present-tense verbs -> "-ing" forms
_DOUBLE = {"run", "hop", "jog", "spin", "squat", "step", "sit", "swim", "skip", "drop", "grab", "trot", "stop",
           "shop", "get", "put", "chop", "flip", "plan", "clap", "tap", "slip", "dip"}
_IRREGULAR = {"lies": "lying", "does": "doing", "goes": "going", "is": "being", "dies": "dying", "ties": "tying",
              "sidesteps": "sidestepping", "tiptoes": "tiptoeing"}


_BASE_IRREGULAR = {"lies": "lie", "dies": "die", "ties": "tie", "is": "be", "has": "have", "tiptoes": "tiptoe",
                   "does": "do", "goes": "go"}


def base_form(verb: str) -> str:
    """Third-person present verb -> base form ('walks' -> 'walk', 'dashes' -> 'dash', 'lies' -> 'lie')."""
    v = verb.lower()
    if v in _BASE_IRREGULAR:
        return _BASE_IRREGULAR[v]
    if v.endswith("sses") or re.search(r"(ss|sh|ch|x|z|o)es$", v):
        return v[:-2]
    if v.endswith("ies"):
        return v[:-3] + "y"
    if v.endswith("s") and not v.endswith("ss"):
        return v[:-1]
    return v


def gerund(verb: str) -> str:
    """Third-person present verb -> -ing form ('walks' -> 'walking', 'runs' -> 'running')."""
    v = verb.lower()
    if v in _IRREGULAR:
        return _IRREGULAR[v]
    base = base_form(v)
    if base in _DOUBLE:
        return base + base[-1] + "ing"
    if base.endswith("ie"):
        return base[:-2] + "ying"
    if base.endswith("e") and not base.endswith(("ee", "ye", "oe")) and len(base) > 2:
        return base[:-1] + "ing"
    return base + "ing"


def progressive(vp: str) -> str:
    """'walks forward' -> 'walking forward', 'jumps and turns' -> 'jumping and turning' (the first
    word is the verb; a known verb after "and" is converted too)."""
    words = vp.split()
    out = [gerund(words[0])] if words else []
    for prev, w in zip(words, words[1:]):
        out.append(gerund(w) if prev == "and" and w in table_verbs() else w)
    return " ".join(out)


def table_verbs() -> set:
    """The verbs the phrase tables start with ('walks', 'turns', ...)."""
    global _VERBS
    if _VERBS is None:
        tables = [v for vs in BANDAI_CONTENT.values() for v in vs] + [v for vs in HDM05_CLASSES.values() for v in vs]
        tables += [v for vs in DEEPMIMIC_MOTIONS.values() for v in vs] + [p for a in ACTIONS.values() for p in a.phrases]
        _VERBS = {vp.split()[0] for vp in tables} | {"turns", "stands", "puts", "grabs", "kicks", "spins", "turning"}
    return _VERBS


_VERBS = None


def _seed(clip_id: str) -> int:
    return int(hashlib.sha1(clip_id.encode()).hexdigest()[:8], 16)


def _pick(clip_id: str, options: list[str], n: int) -> list[str]:
    """Deterministic choice of n distinct options for a clip."""
    seed = _seed(clip_id)
    order = sorted(range(len(options)), key=lambda i: (i * 7919 + seed) % 104729)
    out: list[str] = []
    for i in order:
        s = options[i]
        if s not in out:
            out.append(s)
        if len(out) == n:
            break
    return out


def _tidy(s: str) -> str:
    s = re.sub(r"\s+", " ", s).strip()
    s = s.replace(" .", ".").replace(" ,", ",").replace("..", ".")
    if s and not s.endswith((".", "!", "?")):
        s += "."
    return s[0].upper() + s[1:] if s else s


def sentences(vps: list[str], manners: list[str] = (), styled_subject: str | None = None) -> list[list[str]]:
    """Every sentence for verb phrases ``vps`` (third person present) and optional manner phrases or
    adverbs, grouped by sentence shape: "{subject} {vp} {manner}.", "{subject} is {vp-ing}
    {manner}.", "{Manner}, {subject} {vp}.", "{styled subject} {vp}." / "... is {vp-ing}."
    (lower case; ``augment`` tidies)."""
    plain, prog, front, styled = [], [], [], []
    tail = [f" {m}" for m in manners] or [""]
    for vp in vps:
        ing = progressive(vp)
        for subj in SUBJECTS:
            for m in tail:
                plain.append(f"{subj} {vp}{m}.")
                prog.append(f"{subj} is {ing}{m}.")
            for m in manners:
                if "," not in m and " like " not in m:
                    front.append(f"{m}, {subj} {vp}.")
        if styled_subject:
            styled += [f"{styled_subject} {vp}.", f"{styled_subject} is {ing}."]
    return [g for g in (plain, prog, front, styled) if g]


def augment(clip_id: str, vps: list[str], manners: list[str] = (), styled_subject: str | None = None,
            n: int = N_CAPTIONS) -> list[str]:
    """n varied captions: first the plainest ("A person {vps[0]}{ manner}."), then seeded picks
    taking the sentence shapes in turn (so every shape appears once n allows it)."""
    first = f"a person {vps[0]}" + (f" {manners[0]}" if manners else "") + "."
    groups = [_pick(f"{clip_id}/{k}", [s for s in g if s != first], len(g)) for k, g in
              enumerate(sentences(vps, manners, styled_subject))]
    out = [first]
    while len(out) < n and any(groups):
        for g in groups:
            if g and len(out) < n:
                out.append(g.pop(0))
    return [_tidy(s) for s in out]


def bandai_captions(content: str, style: str, clip_id: str, n: int = N_CAPTIONS) -> list[str]:
    if content not in BANDAI_CONTENT:
        raise KeyError(f"unknown Bandai content label {content!r}")
    subj, manners = BANDAI_STYLE.get(style, ("a person", [f"in a {style.replace('-', ' ')} style"]))
    return augment(clip_id, BANDAI_CONTENT[content], manners, subj if subj != "a person" else None, n)


def split_camel(name: str) -> str:
    return re.sub(r"(?<=[a-z])(?=[A-Z0-9])|(?<=[A-Z])(?=[A-Z][a-z])", " ", name).lower()


def _prefix(table: dict, key: str):
    for k in sorted(table, key=len, reverse=True):
        if key.startswith(k):
            return table[k]
    return None


def hdm05_phrase(cls: str) -> str:
    """'kickLFront1Reps' -> 'kicks forward with the left leg' (prefix match on known classes)."""
    vps = _prefix(HDM05_CLASSES, cls)
    if vps:
        return vps[0]
    base = re.sub(r"\d+(Reps|hops|Steps).*$", "", cls)
    return "performs the action " + split_camel(base)


def hdm05_captions(cls: str, clip_id: str, n: int = N_CAPTIONS) -> list[str]:
    vps = list(_prefix(HDM05_CLASSES, cls) or [hdm05_phrase(cls)])
    reps = re.search(r"(\d+)Reps", cls)
    manners = ["once"] if reps and reps.group(1) == "1" and not vps[0].startswith("performs") else []
    caps = augment(clip_id, vps, [], None, n)
    if manners:  # a one-repetition clip says so in one of its sentences
        caps[-1] = _tidy(f"a person {vps[0]} once.")
    return caps


def deepmimic_captions(motion: str, clip_id: str, n: int = N_CAPTIONS) -> list[str]:
    """Captions of a DeepMimic clip from its motion name ('long_walk2_mirror' -> walks around)."""
    vps = _prefix(DEEPMIMIC_MOTIONS, motion)
    if vps is None:
        vps = [f"performs a {motion.replace('_', ' ')} motion"]
    return augment(clip_id, list(vps), [], None, n)


def _action_vp(name: str) -> str:
    return ACTIONS[name].phrases[0]


def join_sequence(vps: list[str]) -> str:
    """['does jumping jacks', 'does a squat', 'jogs'] -> 'does jumping jacks, does a squat, then jogs'."""
    if len(vps) == 1:
        return vps[0]
    return ", ".join(vps[:-1]) + ", then " + vps[-1]


def cmu_styles(description: str) -> list[str]:
    """Adverbs for the style words in a CMU description ('TooCoolWalk' -> exaggerated cool swagger)."""
    text = " " + split_words(description).replace("-", " ") + " "
    out = []
    for key in sorted(CMU_STYLES, key=len, reverse=True):
        if f" {key} " in text:
            out.append(CMU_STYLES[key])
            text = text.replace(f" {key} ", " ")
    return out


def description_actions(desc: str) -> tuple[list[str], list[str]]:
    """(actions of the scene, actions of the comma-separated parts in order) of a CMU index
    description "scene - part, part/alternative, ..." (an alternative counts once)."""
    scene, detail = desc.split(" - ", 1) if " - " in desc else ("", desc)
    scene_acts = specific(find_actions(scene))
    seq: list[str] = []
    for part in [p.strip() for p in detail.split(",") if p.strip()]:
        acts = specific(find_actions(part.split("/")[0]) or find_actions(part))
        seq += [a for a in acts[:1] if a not in seq and a not in scene_acts]
    return scene_acts, seq


def cmu_captions(trial: str, kit: dict | None, index_desc: str | None, n: int = N_CAPTIONS) -> list[str]:
    """KIT-ML sentences for the trial where present, then sentences built from the CMU index
    description: its actions (a trial listing several says what it holds, in order: "does jumping
    jacks, does side twists, then jogs"), its style words as adverbs, and its details."""
    out: list[str] = []
    if kit and trial in kit:
        out += [_tidy(seg["text"].strip()) for seg in kit[trial] if str(seg.get("text", "")).strip()]
    desc = (index_desc or "").strip().rstrip(".")
    if not desc:
        return out
    scene, detail = desc.split(" - ", 1) if " - " in desc else ("", desc)
    scene_acts, seq = description_actions(desc)
    detail_words = split_words(detail)
    gen: list[str] = []
    if len(seq) >= 2 and not {"dance", "ballet"} & set(scene_acts + seq):
        vps = [_action_vp(a) for a in scene_acts[:1] + seq]
        chain = join_sequence(vps)
        gen = [_tidy(f"{subj} {chain}.") for subj in ("a person", "someone", "the person")]
        lead = f"{scene}: " if scene else ""
        gen.append(_tidy(f"{lead}a person does several things in a row: {detail_words}."))
    elif scene_acts or seq:
        main = (scene_acts + seq)[0]
        vps = list(ACTIONS[main].phrases)
        manners = cmu_styles(detail)
        gen = augment(f"cmu_{trial}", vps, manners[:1], None, max(2, n - len(out)))
        if scene or len(scene_acts + seq) > 1 or (not manners and detail_words not in (main, main + "s")):
            gen.append(_tidy(f"a person {vps[0]}: {detail_words}."))
    else:
        lead = f"{scene}: " if scene else ""
        gen = [_tidy(f"{lead}a person does this: {detail_words}.")]
    return out + [g for g in gen if g not in out]
