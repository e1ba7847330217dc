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
"""
from __future__ import annotations

import torch
from torch import nn

from ..errors import ShapeMoveError

HEAD_KINDS = ("mlp", "text")


class BetaHead(nn.Module):
    kind = "mlp"
    reads_text = False

    def __init__(self, d_model: int, num_betas: int = 10, hidden: int = 256):
        super().__init__()
        self.sizes = {"d_model": int(d_model), "num_betas": int(num_betas), "hidden": int(hidden)}
        self.net = nn.Sequential(nn.Linear(d_model, hidden), nn.GELU(), nn.Linear(hidden, hidden), nn.GELU(),
                                 nn.Linear(hidden, num_betas))

    def forward(self, hidden_at_beta: torch.Tensor, text=None, text_mask=None) -> torch.Tensor:
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
                 queries: int = 4, heads: int = 4, sliders: int = 0, phenotype_map=None):
        super().__init__()
        if width % heads:
            raise ShapeMoveError(f"beta head: width {width} is not a multiple of heads {heads}")
        self.sizes = {"d_model": int(d_model), "num_betas": int(num_betas), "hidden": int(hidden),
                      "text_dim": int(text_dim), "width": int(width), "queries": int(queries), "heads": int(heads)}
        if sliders:
            self.sizes["sliders"] = int(sliders)
            self._slider_buffers(int(sliders), num_betas, phenotype_map)
        self.text_in = nn.Sequential(nn.LayerNorm(text_dim), nn.Linear(text_dim, width))
        self.position = nn.Embedding(64, width)   # token order ("6 ft 2" is not "2 ft 6"); longer texts share the last
        self.none = nn.Parameter(torch.zeros(1, 1, width))  # the "no shape words" slot
        self.mix = nn.TransformerEncoderLayer(width, heads, 2 * width, dropout=0.0, batch_first=True, norm_first=True)
        self.queries = nn.Parameter(torch.randn(queries, width) * 0.02)
        self.pool = nn.MultiheadAttention(width, heads, batch_first=True)
        self.net = nn.Sequential(nn.Linear(d_model + queries * width, hidden), nn.GELU(), nn.Linear(hidden, hidden),
                                 nn.GELU(), nn.Linear(hidden, num_betas + int(sliders)))

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

    def forward(self, hidden_at_beta: torch.Tensor, text: torch.Tensor | None = None,
                text_mask: torch.Tensor | None = None) -> torch.Tensor:
        B = hidden_at_beta.shape[0]
        if text is None or text.shape[1] == 0:
            text = hidden_at_beta.new_zeros(B, 0, self.sizes["text_dim"])
            text_mask = torch.zeros(B, 0, dtype=torch.bool, device=hidden_at_beta.device)
        L = text.shape[1]
        pos = torch.arange(L, device=text.device).clamp(max=self.position.num_embeddings - 1)
        x = torch.cat([self.none.expand(B, 1, -1), self.text_in(text) + self.position(pos)[None]], 1)
        keep = torch.cat([torch.ones(B, 1, dtype=torch.bool, device=x.device), text_mask.bool()], 1)
        x = self.mix(x, src_key_padding_mask=~keep)
        q = self.queries[None].expand(B, -1, -1)
        pooled, _ = self.pool(q, x, x, key_padding_mask=~keep, need_weights=False)
        out = self.net(torch.cat([hidden_at_beta, pooled.reshape(B, -1)], 1))
        P = self.sizes.get("sliders", 0)
        if not P:
            return out
        sliders = self.slider_mid + out[:, :P] * self.slider_half
        return self.map_intercept + sliders @ self.map_matrix + out[:, P:] @ self.map_null

    def config(self) -> dict:
        return {"kind": self.kind, **self.sizes}


def build_head(config: dict | None, d_model: int, phenotype_map=None) -> nn.Module:
    """The head a saved ``"beta_head"`` entry describes (None: the first kind, ``BetaHead(d_model)``).
    ``phenotype_map``: OpenBody's, for a new head that writes sliders (a loaded one reads its buffers)."""
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
    try:
        return cls(**sizes)
    except TypeError as exc:
        raise ShapeMoveError(f"[BETA] head config {config!r} does not fit the {config['kind']!r} head ({exc})") from None
