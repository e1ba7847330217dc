"""Decoding ShapeMove's output: `[BETA]`, `[SOM]`, then only motion codes until `[EOM]`.

Logits are masked so that nothing but motion tokens (and `[EOM]` once the minimum length is
reached) can appear in the motion span; `[EOM]` is forced at the maximum length. The betas come
from the decoder state whose input is `[BETA]`. Batched; sampling with temperature/top-k, or
greedy at temperature 0. The decoder keeps its key/value cache between steps (one new token per
step), for either encoder (``ShapeMoveT5.encode``/``step``).

Classifier-free guidance (``guidance`` s > 0, ``null_inputs``: the same requests with an empty
motion text, which a model trained with ``null_share`` knows): every step also runs the decoder on
the null inputs and samples from ``cond + s * (cond - uncond)`` logits, so tokens that the prompt
makes likelier than no prompt at all are favoured. The betas come from the conditional rows.
"""
from __future__ import annotations

from dataclasses import dataclass

import torch

from .motion_codes import base_of, token_limit


@dataclass
class Decoded:
    codes: list[list[int]]   # per sample, FSQ indices 0..999
    betas: torch.Tensor      # (B,10)
    token_ids: list[list[int]]


def motion_mask(vocab, vocab_size: int, allow_end: bool) -> torch.Tensor:
    """Additive logit mask: 0 for motion codes (and [EOM] when allowed), -inf elsewhere."""
    mask = torch.full((vocab_size,), float("-inf"))
    mask[vocab.first_code_id: vocab.first_code_id + vocab.num_codes] = 0.0
    if allow_end:
        mask[vocab.eom_id] = 0.0
    return mask


def _prefix_rows(prefix_codes, rows: int, num_codes: int) -> list[list[int]]:
    """One list of prefix codes per row: a flat list shared by all rows, or a list per row."""
    p = list(prefix_codes or [])
    per_row = bool(p) and isinstance(p[0], (list, tuple))
    out = [[int(c) for c in r] for r in p] if per_row else [[int(c) for c in p]] * rows
    if len(out) != rows or len({len(r) for r in out}) > 1:
        raise ValueError(f"per-row prefix codes: {rows} rows of one length needed")
    if any(not 0 <= c < token_limit(num_codes) for r in out for c in r):
        raise ValueError(f"prefix codes must be motion tokens (0..{num_codes - 1}, or with a residual packed in)")
    return [base_of(r, num_codes) for r in out]  # the T5 reads base codes: a packed residual is dropped


@torch.no_grad()
def decode(model, inputs: tuple, min_codes: int, max_codes: int, temperature: float = 1.0,
           top_k: int | None = None, generator: torch.Generator | None = None, guidance: float = 0.0,
           null_inputs: tuple | None = None, prefix_codes: list[int] | None = None) -> Decoded:
    """``inputs``: ``model.inputs_for(...)`` (token ids + mask for a T5, states + mask + segments
    for MiniLM); ``null_inputs`` the same for the empty motion text, needed when ``guidance`` > 0.
    ``prefix_codes``: motion codes (tokens; a residual packed in is dropped) already written after ``[SOM]`` for every row
    (e.g. the last tokens of the previous segment of a timeline), or one list per row, all of one
    length (the starts of retrieved clips, ``retrieval_seeds``): the decoder continues from them;
    ``codes`` holds only the new ones and ``min_codes``/``max_codes`` count only those."""
    vocab = model.vocab
    enc, enc_mask = model.encode(*inputs)
    B = enc.shape[0]
    start = vocab.pad_id  # decoder_start_token_id of every ShapeMove decoder
    rows = _prefix_rows(prefix_codes, B, vocab.num_codes)
    seq = torch.tensor([[start, vocab.beta_id, vocab.som_id] + [vocab.first_code_id + c for c in r] for r in rows],
                       dtype=torch.long)
    # the state whose input is [BETA] (position 1) gives the betas
    logits, hidden, past = model.step(enc, enc_mask, seq, use_cache=True)
    betas = model.betas_at(hidden[:, 1], inputs)
    guided = guidance > 0
    if guided:
        if null_inputs is None:
            raise ValueError("guidance needs null_inputs")
        enc0, mask0 = model.encode(*null_inputs)
        logits0, _, past0 = model.step(enc0, mask0, seq, use_cache=True)
    V = logits.shape[-1]
    mask_open, mask_closed = motion_mask(vocab, V, True), motion_mask(vocab, V, False)
    done = torch.zeros(B, dtype=torch.bool)
    codes: list[list[int]] = [[] for _ in range(B)]
    for step in range(max_codes + 1):
        logits = logits[:, -1].float()
        if guided:
            cond = logits
            logits = cond + guidance * (cond - logits0[:, -1].float())
        if step >= max_codes:  # forced end
            nxt = torch.full((B,), vocab.eom_id, dtype=torch.long)
        else:
            logits = logits + (mask_open if step >= min_codes else mask_closed)
            if temperature <= 0:
                nxt = logits.argmax(-1)
            else:
                logits = logits / temperature
                if top_k:
                    kth = logits.topk(min(int(top_k), V), dim=-1).values[:, -1:]
                    logits = logits.masked_fill(logits < kth, float("-inf"))
                nxt = torch.multinomial(torch.softmax(logits, -1), 1, generator=generator).squeeze(1)
        nxt = torch.where(done, torch.full_like(nxt, vocab.pad_id), nxt)
        for b in range(B):
            if not done[b] and vocab.is_code(nxt[b]):
                codes[b].append(int(nxt[b]) - vocab.first_code_id)
        done |= nxt == vocab.eom_id
        seq = torch.cat([seq, nxt[:, None]], 1)
        if done.all():
            break
        logits, _, past = model.step(enc, enc_mask, nxt[:, None], past=past, use_cache=True)
        if guided:
            logits0, _, past0 = model.step(enc0, mask0, nxt[:, None], past=past0, use_cache=True)
    return Decoded(codes=codes, betas=betas, token_ids=seq[:, 1:].tolist())
