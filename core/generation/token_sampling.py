"""Motion codes for one prompt, N samples at once, optionally continuing from given codes.

``sample_codes`` is the T5 step that ``loop`` (seam candidates) and ``sequence`` (a timeline whose
segments continue from the previous segment's last codes, ``prefix_codes`` of
``constrained_decoding.decode``) share: the prompt and shape text read once, ``n`` rows sampled
with the generator's default guidance, one seeded ``torch.Generator``. Rows that share the
encoder pass differ only by sampling; the [BETA] state does not depend on the sampled tokens.
"""
from __future__ import annotations

import numpy as np
import torch

from ..errors import ShapeMoveError
from ..models.constrained_decoding import decode
from ..models.shapemove_t5 import NULL_PROMPT
from ..torch_threads import one_torch_thread


@torch.no_grad()
def sample_codes(gen, prompt: str, shape_text: str | None, n: int, min_codes: int, max_codes: int, seed: int = 0,
                 temperature: float = 1.0, top_k: int | None = 50, guidance: float | None = None,
                 prefix: list[int] | None = None) -> tuple[list[list[int]], np.ndarray]:
    """``n`` samples of motion codes for ``prompt`` on ``gen`` (a ``Generator``) -> (codes per
    sample, without the prefix; the [BETA] head's betas (10,))."""
    if gen.t5 is None:
        raise ShapeMoveError(f"{gen.model_dir} has no t5/ model: text-to-motion needs one (train t5)")
    n = max(1, int(n)) if temperature > 0 else 1
    with one_torch_thread():
        g = torch.Generator().manual_seed(int(seed))
        inputs = gen.t5.inputs_for(gen.tok, [prompt] * n, [shape_text] * n)
        s = gen.default_guidance if guidance is None else float(guidance)
        null = gen.t5.inputs_for(gen.tok, [NULL_PROMPT] * n, [shape_text] * n) if s > 0 else None
        out = decode(gen.t5, inputs, min_codes, max_codes, temperature=temperature, top_k=top_k, generator=g,
                     guidance=s, null_inputs=null, prefix_codes=list(prefix or []))
    return out.codes, out.betas[0].numpy().astype(np.float32)


def body_for(gen, prompt: str, shape_text: str | None, betas, predicted) -> tuple[np.ndarray, str]:
    """(betas, where they came from) of a request: given betas, else ``gen.body_shape``, as for a
    single prompt: a shape text's measurements or the [BETA] head's reading of it; without one, the
    prompt's person words ("a short, stocky woman walks, then sits down") or the average adult."""
    if betas is not None:
        from .decode import check_betas

        return check_betas(betas), "given"
    from .request import Request

    return gen.body_shape(Request(prompt, shape_text, None), np.asarray(predicted, np.float32))
