"""The numbers a text states, as values beside the word pieces that spell them.

MiniLM reads "188" as a word piece whose state says little of its size, and "1.88" as three
pieces; a head that must turn "188 cm" or "6 ft 2, 200 lb" into a body within a centimetre
has to look the values up from those states. ``number_features`` gives each token of a text
the value of the number its characters belong to (digits with an optional decimal part), in
a few scales, and zeros for the other tokens:

    feats = number_features(tokenizer, ["a man, 6 ft 2, 200 lb"])   # list of (L_i, FEATURES) tensors

Only the values are read here: what a number measures (centimetres, pounds, feet and inches,
an age) is left to the model, which learns it from the words around the number, as it learns
what "tall" or "grandmother" says. The tokens are the tokenizer's own, special tokens included,
so row ``i`` sits beside MiniLM state ``i`` of the same text.
"""
from __future__ import annotations

import math
import re

import torch

NUMBER = re.compile(r"\d+(?:\.\d+)?")
FEATURES = 6


def value_features(v: float) -> list[float]:
    """A number's value in scales a small network can use: a flag, the value over 10 and over 100
    squashed (tanh), over 100 plain (10 from 1,000 up), over 1,000 squashed, and its logarithm."""
    return [1.0, math.tanh(v / 10.0), math.tanh(v / 100.0), v / 100.0 if v < 1000 else 10.0,
            math.tanh(v / 1000.0), math.log10(1.0 + v) / 3.0]


def number_features(tokenizer, texts: list[str]) -> list[torch.Tensor]:
    """Per text, a (L, FEATURES) float tensor: row i is the value of the number that token i of
    ``tokenizer.encode(text)`` spells (zeros where it spells none)."""
    out = []
    for text, enc in zip(texts, tokenizer.encode_batch([str(t) for t in texts])):
        spans = [(m.start(), m.end(), float(m.group())) for m in NUMBER.finditer(str(text))]
        rows = torch.zeros(len(enc.ids), FEATURES)
        if spans:
            for i, (a, b) in enumerate(enc.offsets):
                if b <= a:       # special tokens ([CLS], [SEP]) cover no characters
                    continue
                for s, e, v in spans:
                    if a < e and s < b:
                        rows[i] = torch.tensor(value_features(v))
                        break
        out.append(rows)
    return out
