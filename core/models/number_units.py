"""Which unit each number of a shape text is in, read from the words around it.

"6 ft 2, 200 lb" states a height of 6 x 30.48 + 2 x 2.54 cm and a mass of 200 x 0.4536 kg. A head
that learns a free scale per number has to find 30.48 or 0.4536 by regression, and while its
scales are still wrong, stating a number makes the body worse (the gates close first). Here the
scales are the units' own and fixed; what is learnt is the choice among them: per number (its
first word piece), a softmax over ``UNITS`` from the MiniLM states of a few word pieces either side
("200" followed by "lb"; the "2" after "ft"; "72" before "-year-old" is none of them). The stated
height is the sum over numbers of value x the chosen height unit's scale, and the same for mass.

    units = NumberUnits(text_dim=384)
    said = units(guess, text_states, numbers)   # (B, 2) cm, kg

With ``values`` False (a head's ``"unit_values": 0``; tried, the shipped head reads the values) the
choice never sees the number itself: its value is not an input and its digits' word pieces are hidden from the window, so "20
stone" is read like "9 stone" although no training body weighed 20 stone.

``guess`` (B, 2) stands in as far as no number is read as a height (mass): a body described in
words alone keeps its own size. In training the choice is a softmax; in use (``eval()``), the
likeliest unit. It learns from labels (``unit_labels``: the units that make a text's
numbers add up to its body's own height and mass), by cross-entropy.
"""
from __future__ import annotations

import torch
from torch import nn

from ..text.shape_words import INCH, LB, ST

# (name, which size it states: 0 height cm / 1 mass kg / -1 none, scale to cm or kg)
UNITS = (("none", -1, 0.0),
         ("cm", 0, 1.0), ("m", 0, 100.0), ("mm", 0, 0.1), ("ft", 0, 12 * INCH), ("in", 0, INCH),
         ("kg", 1, 1.0), ("lb", 1, LB), ("st", 1, ST))
WINDOW = (-2, -1, 0, 1, 2, 3)   # word pieces read around a number's first one ("1" "." "88" "m")


def number_starts(numbers: torch.Tensor) -> tuple:
    """(B, L) mask of the word pieces that start a number, and (B, L) the values they spell, from
    ``text_numbers`` features (B, L, F): all pieces of "1.88" carry 1.88, only the first counts."""
    flag, value = numbers[..., 0], numbers[..., 3] * 100.0
    prev_flag = torch.cat([torch.zeros_like(flag[:, :1]), flag[:, :-1]], 1)
    prev_value = torch.cat([torch.zeros_like(value[:, :1]), value[:, :-1]], 1)
    return (flag > 0) & ~((prev_flag > 0) & (prev_value == value)), value


class NumberUnits(nn.Module):
    def __init__(self, text_dim: int = 384, width: int = 64, hidden: int = 256, features: int = 6,
                 values: bool = True):
        super().__init__()
        self.values = bool(values)   # False: the choice reads the words around a number, never the number
        self.read = nn.Sequential(nn.LayerNorm(text_dim), nn.Linear(text_dim, width))
        self.choose = nn.Sequential(nn.Linear(len(WINDOW) * width + (features if values else 0), hidden), nn.GELU(),
                                    nn.Linear(hidden, len(UNITS)))
        with torch.no_grad():   # at first every number is read as none: the body keeps its size
            self.choose[-1].weight.mul_(0.1)
            self.choose[-1].bias.zero_()
            self.choose[-1].bias[0] = 4.0
        sizes = torch.tensor([u[1] for u in UNITS])
        scale = torch.tensor([u[2] for u in UNITS])
        self.register_buffer("to_size", torch.stack([(sizes == k).float() * scale for k in (0, 1)], 1),
                             persistent=False)   # (U, 2): a unit's scale into the size it states
        self.register_buffer("counts", torch.stack([(sizes == k).float() for k in (0, 1)], 1), persistent=False)

    def logits(self, text: torch.Tensor, numbers: torch.Tensor) -> tuple:
        """(B, L, U) unit logits of every word piece (meaningful where ``start``), ``start`` (B, L)
        and the values (B, L)."""
        start, value = number_starts(numbers)
        x = self.read(text.to(self.read[1].weight.dtype))
        if not self.values:   # the digits' own word pieces hidden: "20 stone" reads as "_ stone", whatever the size
            x = x * (numbers[..., :1] <= 0).to(x.dtype)
        B, L, W = x.shape
        pad = x.new_zeros(B, max(-min(WINDOW), 0), W), x.new_zeros(B, max(WINDOW), W)
        xp = torch.cat([pad[0], x, pad[1]], 1)
        o = pad[0].shape[1]
        window = torch.cat([xp[:, o + d:o + d + L] for d in WINDOW] + ([numbers.to(x.dtype)] if self.values else []), 2)
        return self.choose(window), start, value

    def forward(self, guess: torch.Tensor, text: torch.Tensor, numbers: torch.Tensor) -> torch.Tensor:
        """(B, 2) height (cm) and mass (kg) the text states, ``guess`` where it states none."""
        logits, start, value = self.logits(text, numbers)
        p = torch.softmax(logits, -1)
        if not self.training:   # in use, each number is in one unit
            p = torch.nn.functional.one_hot(p.argmax(-1), len(UNITS)).to(p.dtype)
        p = p * start[..., None]
        stated = ((p @ self.to_size) * value[..., None]).sum(1)       # (B, 2)
        read = (p @ self.counts).sum(1).clamp(max=1.0)                # how far a size is stated at all
        return (1.0 - read) * guess + stated

    def read_units(self, text: torch.Tensor, numbers: torch.Tensor) -> list[list[tuple[float, str]]]:
        """Per text, (value, unit name) of each number it states: what the head reads (for a user's
        check and the tests)."""
        logits, start, value = self.logits(text, numbers)
        best = logits.argmax(-1)
        return [[(float(value[b, i]), UNITS[int(best[b, i])][0]) for i in torch.nonzero(start[b]).flatten().tolist()]
                for b in range(len(logits))]


HEIGHT_UNITS = tuple(i for i, u in enumerate(UNITS) if u[1] == 0)
MASS_UNITS = tuple(i for i, u in enumerate(UNITS) if u[1] == 1)
PAIRS = ((("ft", "in"), 0), (("m", "cm"), 0), (("st", "lb"), 1))   # two numbers, one size: 6 ft 2, 1,88 m, 14 st 4 lb


def _readings(values: list[float], size: int) -> list[tuple[float, dict]]:
    """Every way ``values`` (a text's numbers, in order) can state one size (0 height, 1 mass): by
    no number, by one number in one unit, or by two numbers in a row in a pair of units; as
    (the size stated or nan, {number index: unit index})."""
    names = {u[0]: i for i, u in enumerate(UNITS)}
    out = [(float("nan"), {})]
    for i, v in enumerate(values):
        for u in HEIGHT_UNITS if size == 0 else MASS_UNITS:
            out.append((v * UNITS[u][2], {i: u}))
    for (a, b), s in PAIRS:
        if s == size:
            for i in range(len(values) - 1):
                out.append((values[i] * UNITS[names[a]][2] + values[i + 1] * UNITS[names[b]][2],
                            {i: names[a], i + 1: names[b]}))
    return out


def unit_labels(values: list[float], height: float, mass: float, tol_cm: float = 1.4, tol_kg: float = 0.7) -> list[int]:
    """The unit of each of a text's numbers that makes them state the height (cm) and mass (kg) of
    the body it describes, within what rounding leaves (``tol_cm``, ``tol_kg``): training labels
    for ``NumberUnits`` from the bodies' own sizes, never from parsing the text. A size no reading
    meets is taken as not stated (its numbers: none); of the readings that meet both, the closest."""
    best, pick = None, {}
    for h, hu in _readings(values, 0):
        if h == h and abs(h - height) > tol_cm:
            continue
        for m, mu in _readings(values, 1):
            if (m == m and abs(m - mass) > tol_kg) or set(hu) & set(mu):
                continue
            # a size read counts for more than a size left unread; then the closer
            key = (-(h == h) - (m == m), (abs(h - height) if h == h else 0.0) / tol_cm + (abs(m - mass) if m == m else 0.0) / tol_kg)
            if best is None or key < best:
                best, pick = key, {**hu, **mu}
    return [pick.get(i, 0) for i in range(len(values))]


def describe(read: list) -> str:
    """"6 ft 2 in = 188.0 cm; 200 lb = 90.7 kg": one text's ``read_units`` as a user reads it ("" when
    it states neither size)."""
    kind = {u[0]: (u[1], u[2]) for u in UNITS}
    parts = []
    for size, unit in ((0, "cm"), (1, "kg")):
        said = [(v, u) for v, u in read if kind[u][0] == size]
        if said:
            total = sum(v * kind[u][1] for v, u in said)
            parts.append(" ".join(f"{v:g} {u}" for v, u in said) + f" = {total:.1f} {unit}")
    return "; ".join(parts)
