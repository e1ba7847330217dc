"""The `[BETA]` projection: the T5 decoder's last hidden state at the `[BETA]` position -> the 10
body-shape betas (the paper's shape head).

Two kinds, recorded in the model folder's ``shapemove.json`` under ``"beta_head"`` (``head_config``;
a folder without that key holds the first kind, as every model saved before it did):

- ``"mlp"`` (``BetaHead``): an MLP on the `[BETA]` state alone;
- ``"text"`` (``TextBetaHead``): the same state AND the frozen MiniLM's token states of the
  prompt's shape text, read by one self-attention layer and pooled by a few learned queries (a
  learned "no words" slot is always there to attend to, so a prompt without shape text pools that
  slot). The decoder is trained for motion and its 128-wide state at `[BETA]` keeps little of the
  words; token-level attention can find "grandmother", "ripped" or the "188" of "188 cm" and the
  "6" and "2" of "6 ft 2" (MiniLM's states carry each token's context).
  With ``sliders`` = P > 0 it writes the body as OpenBody's P phenotype sliders plus a part the
  sliders cannot see: betas = intercept + sliders @ map + residual @ null, where ``null`` projects
  onto the betas the map's rows do not span. Reading the sliders back from those betas by least
  squares (``PhenotypeMap.from_betas``, what the evaluation and the Shape panel do) gives exactly the
  sliders written, so "elderly" or "a woman" can land on its slider without the tiny beta
  directions age lives in having to be hit to a few hundredths. The map rides along in the weights
  (buffers) so the file is the whole head.
  With ``numbers`` = F > 0 each token also carries the value of the number it spells
  (``text_numbers.number_features``: "188" is 188, all three pieces of "1.88" are 1.88), added to
  its state; what the number measures it learns from the words around it. ``reads_numbers``:
  ``ShapeMoveT5.inputs_for`` then appends those features to the inputs.
  With ``meets`` = 1 it also writes the height (cm) and mass (kg) it reads in the text (2: it
  points at the numbers that state them and scales each by what its context says it is, ``_point``;
  where none is stated, the body's own size), and the body it writes is then moved along OpenBody's
  height and weight sliders until its rest mesh measures exactly those (``meet``: a few Newton
  steps on the mesh height, linear in the betas, and the mesh mass, an exact cubic; the arrays ride
  along as buffers). The head's reading of "188 cm, 92 kg" then decides the body's size, not how
  closely 10 betas can be regressed. With ``meets`` = 3 the numbers are read by ``number_units``
  instead: each number's unit (cm, m, ft, in, kg, lb, st or none) chosen from the words around it,
  the scales the units' own. ``number_tokens`` = 0 gives the values to that reader only (the
  token states stay the words'), so a trained head without numbers can take it on unchanged;
  ``unit_values`` = 0 lets the reader choose from the words around a number alone.
"""
from __future__ import annotations

import torch
from torch import nn

from ..body.body_mass import cubic_in_betas
from ..errors import ShapeMoveError

HEAD_KINDS = ("mlp", "text")
MEET_CM, MEET_KG = (130.0, 215.0), (30.0, 180.0)   # the sizes a head that meets them writes at most


class BetaHead(nn.Module):
    kind = "mlp"
    reads_text = False

    def __init__(self, d_model: int, num_betas: int = 10, hidden: int = 256):
        super().__init__()
        self.sizes = {"d_model": int(d_model), "num_betas": int(num_betas), "hidden": int(hidden)}
        self.net = nn.Sequential(nn.Linear(d_model, hidden), nn.GELU(), nn.Linear(hidden, hidden), nn.GELU(),
                                 nn.Linear(hidden, num_betas))

    reads_numbers = False

    def forward(self, hidden_at_beta: torch.Tensor, text=None, text_mask=None, numbers=None) -> torch.Tensor:
        """(B, d_model) -> (B, 10); ``text`` is ignored (this head reads the state alone)."""
        return self.net(hidden_at_beta)

    def config(self) -> dict:
        return {"kind": self.kind, **self.sizes}


class TextBetaHead(nn.Module):
    """`[BETA]` state (B, d_model) + the shape text's MiniLM token states (B, L, text_dim) with
    their mask (B, L) -> (B, 10)."""

    kind = "text"
    reads_text = True

    def __init__(self, d_model: int, num_betas: int = 10, hidden: int = 256, text_dim: int = 384, width: int = 128,
                 queries: int = 4, heads: int = 4, sliders: int = 0, phenotype_map=None, numbers: int = 0,
                 meets: int = 0, size_model: dict | None = None, number_tokens: int = 1, unit_values: int = 1):
        super().__init__()
        if width % heads:
            raise ShapeMoveError(f"beta head: width {width} is not a multiple of heads {heads}")
        self.sizes = {"d_model": int(d_model), "num_betas": int(num_betas), "hidden": int(hidden),
                      "text_dim": int(text_dim), "width": int(width), "queries": int(queries), "heads": int(heads)}
        if sliders:
            self.sizes["sliders"] = int(sliders)
            self._slider_buffers(int(sliders), num_betas, phenotype_map)
        if numbers:
            self.sizes["numbers"] = int(numbers)
            if number_tokens:
                self.number_in = nn.Sequential(nn.Linear(int(numbers), width), nn.GELU(), nn.Linear(width, width))
            else:   # the values go to the unit reader (meets 3) only: the tokens are the words' alone
                self.sizes["number_tokens"] = 0
        if meets:
            if not sliders:
                raise ShapeMoveError("beta head: meets needs sliders (it moves the height and weight sliders)")
            self.sizes["meets"] = int(meets)
            self._size_buffers(num_betas, size_model)
            if int(meets) not in (1, 2, 3):
                raise ShapeMoveError(f"beta head: meets must be 1, 2 or 3, got {meets!r}")
            if int(meets) >= 2 and not numbers:
                raise ShapeMoveError(f"beta head: meets {int(meets)} reads the numbers of the text; it needs numbers")
            if int(meets) == 3:
                from .number_units import NumberUnits
                self.units = NumberUnits(text_dim, features=int(numbers), values=bool(unit_values))
                if not unit_values:
                    self.sizes["unit_values"] = 0
            if int(meets) == 2:
                self.pointer = nn.Linear(width, 4)   # per token: height and mass gate, log of the scale
                with torch.no_grad():
                    self.pointer.weight.mul_(0.1)
                    self.pointer.bias.copy_(torch.tensor([-2.0, -2.0, 0.0, 0.0]))
        self.text_in = nn.Sequential(nn.LayerNorm(text_dim), nn.Linear(text_dim, width))
        self.position = nn.Embedding(64, width)   # token order ("6 ft 2" is not "2 ft 6"); longer texts share the last
        self.none = nn.Parameter(torch.zeros(1, 1, width))  # the "no shape words" slot
        self.mix = nn.TransformerEncoderLayer(width, heads, 2 * width, dropout=0.0, batch_first=True, norm_first=True)
        self.queries = nn.Parameter(torch.randn(queries, width) * 0.02)
        self.pool = nn.MultiheadAttention(width, heads, batch_first=True)
        self.net = nn.Sequential(nn.Linear(d_model + queries * width, hidden), nn.GELU(), nn.Linear(hidden, hidden),
                                 nn.GELU(), nn.Linear(hidden, num_betas + int(sliders) + (2 if meets == 1 else 0)))

    def _slider_buffers(self, P: int, n: int, pmap) -> None:
        """The map (P, n), intercept (n,), null-space projector (n, n) and slider centre/scale (P,):
        from ``pmap`` (OpenBody's PhenotypeMap) when training, zeros until ``load_state_dict`` else."""
        z = {"map_matrix": torch.zeros(P, n), "map_intercept": torch.zeros(n), "map_null": torch.zeros(n, n),
             "slider_mid": torch.zeros(P), "slider_half": torch.ones(P)}
        if pmap is not None:
            M = torch.as_tensor(pmap.matrix, dtype=torch.float64)
            if tuple(M.shape) != (P, n):
                raise ShapeMoveError(f"beta head: a phenotype map of {tuple(M.shape)}, expected {(P, n)}")
            r = torch.as_tensor(pmap.ranges, dtype=torch.float64)
            z = {"map_matrix": M, "map_intercept": torch.as_tensor(pmap.intercept, dtype=torch.float64),
                 "map_null": torch.eye(n, dtype=torch.float64) - M.T @ torch.linalg.solve(M @ M.T, M),
                 "slider_mid": r.mean(1), "slider_half": (r[:, 1] - r[:, 0]) / 2}
        for k, v in z.items():
            self.register_buffer(k, v.float())

    SIZE_BUFFERS = ("size_y0", "size_yd", "mass_c", "mass_l", "mass_q", "mass_k", "meet_dirs")

    def _size_buffers(self, n: int, size_model: dict | None) -> None:
        """``size_model`` (``Readback.size_model``): rest-vertex heights y0 (V,) + yd (V, n) @ betas in
        metres, the mass polynomial (kg: c + l.b + b'qb + k[b,b,b]) and the betas of one slider range
        of height and of weight (2, n); zeros (one vertex) until ``load_state_dict`` without it."""
        if size_model is None:
            size_model = {"size_y0": torch.zeros(1), "size_yd": torch.zeros(1, n), "mass_c": torch.zeros(1),
                          "mass_l": torch.zeros(n), "mass_q": torch.zeros(n, n), "mass_k": torch.zeros(n, n, n),
                          "meet_dirs": torch.zeros(2, n)}
        for k in self.SIZE_BUFFERS:
            self.register_buffer(k, torch.as_tensor(size_model[k], dtype=torch.float32).clone())

    def _load_from_state_dict(self, state_dict, prefix, *args, **kwargs):
        # the vertex count of the size buffers is the body's: take the saved shape
        for k in self.SIZE_BUFFERS if self.sizes.get("meets") else ():
            if prefix + k in state_dict and getattr(self, k).shape != state_dict[prefix + k].shape:
                setattr(self, k, torch.zeros_like(state_dict[prefix + k]))
        super()._load_from_state_dict(state_dict, prefix, *args, **kwargs)

    def height_mass(self, betas: torch.Tensor) -> tuple:
        """(B,) rest-mesh height (cm) and mass (kg) of (B, n) betas, and their gradients (B, n)."""
        ys = self.size_y0[None] + betas @ self.size_yd.T
        top, bottom = ys.argmax(1), ys.argmin(1)
        height = 100.0 * (ys.gather(1, top[:, None]) - ys.gather(1, bottom[:, None]))[:, 0]
        g_height = 100.0 * (self.size_yd[top] - self.size_yd[bottom])
        k = self.mass_k
        six = cubic_in_betas(betas, self.mass_c, self.mass_l, self.mass_q, k)
        ksym = k + k.permute(1, 0, 2) + k.permute(2, 0, 1)
        g_six = self.mass_l + betas @ (self.mass_q + self.mass_q.T) + torch.einsum("pjk,bj,bk->bp", ksym, betas, betas)
        sign = torch.where(six < 0, -1.0, 1.0)
        return height, six.abs(), g_height, sign[:, None] * g_six

    def meet(self, betas: torch.Tensor, target: torch.Tensor, iterations: int = 5) -> torch.Tensor:
        """``betas`` moved along the height and weight slider directions until the rest mesh measures
        ``target`` (B, 2): height cm, mass kg (Newton, each step at most half a slider range)."""
        dirs = self.meet_dirs
        for _ in range(iterations):
            h, m, gh, gm = self.height_mass(betas)
            J = torch.stack([gh @ dirs.T, gm @ dirs.T], 1)            # (B, 2 equations, 2 sliders)
            r = torch.stack([h, m], 1) - target
            det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
            ok = det.abs() > 1e-6
            safe = torch.where(ok, det, torch.ones_like(det))
            step = torch.stack([J[:, 1, 1] * r[:, 0] - J[:, 0, 1] * r[:, 1],
                                -J[:, 1, 0] * r[:, 0] + J[:, 0, 0] * r[:, 1]], 1) / safe[:, None]
            step = torch.where(ok[:, None], step, torch.zeros_like(step)).clamp(-0.5, 0.5)
            betas = betas - step @ dirs
        return betas

    @property
    def reads_numbers(self) -> bool:
        return bool(self.sizes.get("numbers"))

    def forward(self, hidden_at_beta: torch.Tensor, text: torch.Tensor | None = None,
                text_mask: torch.Tensor | None = None, numbers: torch.Tensor | None = None) -> torch.Tensor:
        """``numbers`` (B, L, F): the value features of ``text``'s tokens, for a head that reads them
        (required then, whenever there is text)."""
        B = hidden_at_beta.shape[0]
        if text is None or text.shape[1] == 0:
            text = hidden_at_beta.new_zeros(B, 0, self.sizes["text_dim"])
            text_mask = torch.zeros(B, 0, dtype=torch.bool, device=hidden_at_beta.device)
            numbers = hidden_at_beta.new_zeros(B, 0, self.sizes.get("numbers", 0))
        L = text.shape[1]
        pos = torch.arange(L, device=text.device).clamp(max=self.position.num_embeddings - 1)
        tokens = self.text_in(text) + self.position(pos)[None]
        if self.reads_numbers:
            if numbers is None or tuple(numbers.shape[:2]) != (B, L):
                raise ShapeMoveError("this [BETA] head reads the values of the numbers in the shape text: "
                                     "give it number features for every text token")
            if hasattr(self, "number_in"):
                tokens = tokens + self.number_in(numbers.to(tokens.dtype))
        x = torch.cat([self.none.expand(B, 1, -1), tokens], 1)
        keep = torch.cat([torch.ones(B, 1, dtype=torch.bool, device=x.device), text_mask.bool()], 1)
        x = self.mix(x, src_key_padding_mask=~keep)
        q = self.queries[None].expand(B, -1, -1)
        pooled, _ = self.pool(q, x, x, key_padding_mask=~keep, need_weights=False)
        out = self.net(torch.cat([hidden_at_beta, pooled.reshape(B, -1)], 1))
        P, n = self.sizes.get("sliders", 0), self.sizes["num_betas"]
        if not P:
            return out
        sliders = self.slider_mid + out[:, :P] * self.slider_half
        betas = self.map_intercept + sliders @ self.map_matrix + out[:, P:P + n] @ self.map_null
        if not self.sizes.get("meets"):
            return betas
        if self.sizes["meets"] >= 2:   # the numbers read; the body's own size where none is stated
            height, mass, _, _ = self.height_mass(betas)
            guess = torch.stack([height, mass], 1)
            said = self._point(guess, x[:, 1:], numbers) if self.sizes["meets"] == 2 else self.units(guess, text * text_mask[..., None], numbers)
        else:
            said = torch.stack([170.0 + 20.0 * out[:, P + n], 70.0 + 20.0 * out[:, P + n + 1]], 1)   # cm, kg
        if self.reading_sizes:   # training reads the sizes unclamped: a clamped one has no gradient
            return betas, said
        if self.sizes["meets"] >= 2 and self.refusing:
            refuse_impossible(said, guess)
        return self.meet(betas, torch.stack([said[:, 0].clamp(*MEET_CM), said[:, 1].clamp(*MEET_KG)], 1))

    reading_sizes = False   # training: forward gives (betas before ``meet``, the height and mass read)
    refusing = True         # sizes no body has are an error (``refuse_impossible``); off while a head learns

    def _point(self, guess: torch.Tensor, tokens: torch.Tensor, numbers: torch.Tensor) -> torch.Tensor:
        """(B, 2) height and mass: each number of the text (its first token) may count towards either,
        gated and scaled by what its context says it is (gate ~ 1 and scale ~ 30.48 for the "6" of
        "6 ft 2", ~ 2.54 for its "2"; ~ 0.454 for "200" in "200 lb"), the sum of those standing in for
        ``guess`` (the body's own size: ``meet`` then leaves a body described in words alone as it is)
        as far as the gates add up to 1."""
        from .number_units import number_starts

        start, value = number_starts(numbers)    # a number's first word piece, and its value
        g = self.pointer(tokens)
        gate = torch.sigmoid(g[..., :2]) * start[..., None]
        scale = torch.exp(g[..., 2:].clamp(-4.0, 6.0))
        stated = (gate * scale * value[..., None]).sum(1)                    # (B, 2)
        weight = gate.sum(1).clamp(max=1.0)
        return (1.0 - weight) * guess + stated

    def config(self) -> dict:
        return {"kind": self.kind, **self.sizes}


def refuse_impossible(said: torch.Tensor, guess: torch.Tensor) -> None:
    """A clear error where the sizes a head read in the text ((B, 2) cm, kg; ``guess``: the body's
    own, where the text states none) are no body it can make: a height or mass outside
    ``MEET_CM`` / ``MEET_KG``, or the two a BMI no living body has (``shape_words.PERSON_RANGES``),
    never a body clamped to something else."""
    from ..text.shape_words import PERSON_RANGES

    stated = (said - guess).abs() > 1e-3
    bmi = said[:, 1] / (said[:, 0] / 100.0).clamp(min=0.1) ** 2
    lo, hi = PERSON_RANGES["bmi"]
    for b in torch.nonzero(stated.any(1)).flatten().tolist():
        h, kg = float(said[b, 0]), float(said[b, 1])
        if stated[b, 0] and not MEET_CM[0] <= h <= MEET_CM[1]:
            raise ShapeMoveError(f"the shape text states a height of {h:.0f} cm (as the [BETA] head reads it): "
                                 f"it makes bodies of {MEET_CM[0]:.0f}-{MEET_CM[1]:.0f} cm")
        if stated[b, 1] and not MEET_KG[0] <= kg <= MEET_KG[1]:
            raise ShapeMoveError(f"the shape text states a weight of {kg:.0f} kg (as the [BETA] head reads it): "
                                 f"it makes bodies of {MEET_KG[0]:.0f}-{MEET_KG[1]:.0f} kg")
        if stated[b].all() and not lo <= float(bmi[b]) <= hi:
            raise ShapeMoveError(f"{h:.0f} cm and {kg:.0f} kg make a BMI of {float(bmi[b]):.1f}: no living body "
                                 f"has that (BMI {lo:g}-{hi:g})")


def build_head(config: dict | None, d_model: int, phenotype_map=None, size_model: dict | None = None) -> nn.Module:
    """The head a saved ``"beta_head"`` entry describes (None: the first kind, ``BetaHead(d_model)``).
    ``phenotype_map``: OpenBody's, for a new head that writes sliders; ``size_model``
    (``Readback.size_model``) for a new head that meets the sizes it reads (a loaded one reads its
    buffers)."""
    if config is None:
        return BetaHead(d_model)
    if not isinstance(config, dict) or config.get("kind") not in HEAD_KINDS:
        raise ShapeMoveError(f"unknown [BETA] head {config!r}: expected a kind among {', '.join(HEAD_KINDS)}")
    sizes = {k: v for k, v in config.items() if k != "kind"}
    if sizes.get("d_model", d_model) != d_model:
        raise ShapeMoveError(f"the [BETA] head reads a {sizes['d_model']}-wide state, the decoder writes {d_model}")
    sizes["d_model"] = d_model
    cls = BetaHead if config["kind"] == "mlp" else TextBetaHead
    if sizes.get("sliders") and cls is TextBetaHead:
        sizes["phenotype_map"] = phenotype_map
    if sizes.get("meets") and cls is TextBetaHead:
        sizes["size_model"] = size_model
    try:
        return cls(**sizes)
    except TypeError as exc:
        raise ShapeMoveError(f"[BETA] head config {config!r} does not fit the {config['kind']!r} head ({exc})") from None
