"""Do counted prompts do the thing that many times? Ten prompts that count jumps, hops, squats,
jumping jacks and kicks, each generated on seeds 0-3 at a fixed length; every count is read on the
planted motion's joints, independently of ``core/generation/count_words.py`` (which reads
features): a jump is 3+ frames with no foot contact in which the lowest foot joint clears 8 cm, a
squat 3+ frames with the pelvis 20 cm under its standing height, a jumping jack 3+ frames with both
wrists above the head, a kick 3+ frames with one ankle 50 cm over the other.

    python tools/count_check.py [--model weights/default] [--seeds 4]
"""
from __future__ import annotations

import argparse

import numpy as np

ASKS = [("a man jumps forward twice", 4, "jumps", 2), ("someone does four jumps in place", 4, "jumps", 4),
        ("she hops once", 4, "jumps", 1), ("a man squats twice", 6, "squats", 2),
        ("a woman does four squats", 6, "squats", 4), ("a person does three squats", 6, "squats", 3),
        ("a woman does three jumping jacks", 6, "jacks", 3), ("someone does five jumping jacks", 8, "jacks", 5),
        ("she kicks twice", 4, "kicks", 2), ("a man does three kicks", 6, "kicks", 3)]


def _runs(mask) -> list[tuple[int, int]]:
    from shapemove.core.motion.contacts import runs

    return [(a, b) for a, b in runs(mask) if b - a >= 3]


def count(kind: str, motion) -> int:
    j = motion.joints
    if kind == "jumps":
        air = ~motion.contacts.astype(bool).any(1)
        y = j[:, [7, 8, 10, 11], 1].min(1)
        return sum(1 for a, b in _runs(air) if y[a:b].max() > y.min() + 0.08)
    if kind == "squats":
        return len(_runs(j[:, 0, 1] < np.percentile(j[:, 0, 1], 90) - 0.2))
    if kind == "kicks":
        return len(_runs(np.abs(j[:, 7, 1] - j[:, 8, 1]) > 0.5))
    return len(_runs(np.minimum(j[:, 20, 1], j[:, 21, 1]) > j[:, 15, 1]))


def main() -> None:
    from shapemove.core.generation.generate import Generator, Request

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=None)
    ap.add_argument("--seeds", type=int, default=4)
    a = ap.parse_args()
    gen = Generator(a.model)
    right = 0
    for prompt, seconds, kind, want in ASKS:
        got = [gen.generate_batch([Request(prompt, seconds=seconds, seed=s)])[0] for s in range(a.seeds)]
        counts = [count(kind, m) for m in got]
        right += sum(c == want for c in counts)
        print(f"{prompt!r} ({seconds} s, want {want}): {counts}  {[m.provenance.split(' (')[0] for m in got]}")
    print(f"the asked count {right} of {a.seeds * len(ASKS)} times")


if __name__ == "__main__":
    main()
