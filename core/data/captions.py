"""Natural-language captions from the labels the mocap archives carry.

Bandai: content + style label per clip; HDM05: an action class in the file name; CMU: KIT-ML
sentences where present, else the CMU index description. Each clip gets several varied
sentences (deterministic per clip id, so a rebuild gives the same text).
"""
from __future__ import annotations

import hashlib
import re

# Bandai content labels -> verb phrase (third person, present tense)
BANDAI_CONTENT = {
    "walk": "walks forward",
    "run": "runs forward",
    "dash": "dashes forward at full speed",
    "walk-back": "walks backward",
    "walk-left": "walks sideways to the left",
    "walk-right": "walks sideways to the right",
    "walk-turn-left": "walks and turns to the left",
    "walk-turn-right": "walks and turns to the right",
    "bow": "bows",
    "bye": "waves goodbye with one hand",
    "byebye": "waves goodbye with both hands",
    "guide": "guides someone with an open-hand gesture",
    "respond": "raises a hand to respond",
    "call": "beckons someone to come over",
    "punch": "throws punches",
    "kick": "kicks",
    "slash": "slashes with a sword",
    "dance-long": "dances",
    "dance-short": "does a short dance",
    "wave-both-hands": "waves with both hands",
    "wave-left-hand": "waves with the left hand",
    "wave-right-hand": "waves with the right hand",
    "raise-up-both-hands": "raises both hands",
    "raise-up-left-hand": "raises the left hand",
    "raise-up-right-hand": "raises the right hand",
}

# Bandai style labels -> (subject noun phrase, manner phrase)
BANDAI_STYLE = {
    "normal": ("a person", "in a normal way"),
    "happy": ("a happy person", "happily"),
    "sad": ("a sad person", "sadly"),
    "angry": ("an angry person", "angrily"),
    "proud": ("a proud person", "proudly"),
    "not-confident": ("an unconfident person", "without confidence"),
    "masculinity": ("a person", "in a masculine manner"),
    "masculine": ("a person", "in a masculine manner"),
    "feminine": ("a person", "in a feminine manner"),
    "childish": ("a childlike person", "in a childish way"),
    "youthful": ("a young person", "energetically, with youthful vigour"),
    "old": ("an old person", "slowly, like an old person"),
    "elderly": ("an elderly person", "slowly, like an elderly person"),
    "tired": ("a tired person", "wearily"),
    "exhausted": ("an exhausted person", "with exhaustion"),
    "active": ("an energetic person", "actively"),
    "musical": ("a person", "rhythmically, like in a musical"),
    "giant": ("a person", "with heavy steps, like a giant"),
    "chimpira": ("a person", "with a swagger, like a street thug"),
}

HDM05_CLASSES = {
    "squat": "does a squat",
    "hopBothLegs": "hops on both legs",
    "depositFloorR": "bends down and puts something on the floor with the right hand",
    "kickLFront": "kicks forward with the left leg",
    "grabHighR": "reaches up high and grabs something with the right hand",
    "elbowToKnee": "touches each elbow to the opposite knee",
    "lieDownFloor": "lies down on the floor",
    "rotateArmsBothBackward": "rotates both arms backward",
    "jogLeftCircle": "jogs in a circle to the left",
    "sneak": "sneaks forward",
    "throwBasketball": "throws a basketball",
}

_TEMPLATES = [
    "{subj} {vp}.",
    "a person {vp} {manner}.",
    "someone {vp} {manner}.",
    "the person {vp}.",
]


def _pick(clip_id: str, options: list[str], n: int) -> list[str]:
    """Deterministic choice of n distinct options for a clip."""
    seed = int(hashlib.sha1(clip_id.encode()).hexdigest()[:8], 16)
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
    s = s.replace(" .", ".")
    return s[0].upper() + s[1:] if s else s


def bandai_captions(content: str, style: str, clip_id: str, n: int = 3) -> list[str]:
    if content not in BANDAI_CONTENT:
        raise KeyError(f"unknown Bandai content label {content!r}")
    vp = BANDAI_CONTENT[content]
    subj, manner = BANDAI_STYLE.get(style, ("a person", f"in a {style.replace('-', ' ')} style"))
    options = [t.format(subj=subj, vp=vp, manner=manner) for t in _TEMPLATES]
    if style == "normal":  # "in a normal way" adds nothing: prefer the plain sentences
        options = [f"a person {vp}.", f"someone {vp}.", f"the person {vp}."]
    return [_tidy(s) for s in _pick(clip_id, options, n)]


def split_camel(name: str) -> str:
    return re.sub(r"(?<=[a-z])(?=[A-Z0-9])|(?<=[A-Z])(?=[A-Z][a-z])", " ", name).lower()


def hdm05_phrase(cls: str) -> str:
    """'kickLFront1Reps' -> 'kicks forward with the left leg' (prefix match on known classes)."""
    for key in sorted(HDM05_CLASSES, key=len, reverse=True):
        if cls.startswith(key):
            return HDM05_CLASSES[key]
    base = re.sub(r"\d+(Reps|hops|Steps).*$", "", cls)
    return "performs the action " + split_camel(base)


def hdm05_captions(cls: str, clip_id: str, n: int = 3) -> list[str]:
    vp = hdm05_phrase(cls)
    reps = re.search(r"(\d+)Reps", cls)
    extra = []
    if reps and reps.group(1) == "1":
        extra = [f"a person {vp} once."]
    options = [f"a person {vp}.", f"someone {vp}.", f"the person {vp}.", f"a man {vp}."] + extra
    return [_tidy(s) for s in _pick(clip_id, options, n)]


def cmu_captions(trial: str, kit: dict | None, index_desc: str | None, n: int = 3) -> list[str]:
    """KIT-ML sentences for the trial where present, else the CMU index description."""
    if kit and trial in kit:
        texts = [seg["text"].strip() for seg in kit[trial] if seg.get("text", "").strip()]
        if texts:
            return [_tidy(t) for t in texts]
    if index_desc:
        desc = index_desc.strip().rstrip(".")
        if " - " in desc:
            scene, act = desc.split(" - ", 1)
            options = [f"{scene}: a person does this: {act}.", f"a person, {scene}: {act}."]
        else:
            options = [f"a person does this: {desc}.", f"someone's motion: {desc}."]
        return [_tidy(s) for s in options[:n]]
    return []
