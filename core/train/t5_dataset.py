"""Training examples for ShapeMove's T5: motion tokens from the frozen SA-VAE + captions + shape texts.

``tokenize_clips`` runs the SA-VAE encoder once over each clip's normalized features and caches
the FSQ indices. ``T2MExamples`` draws (input text, target tokens, betas) pairs: the input is the
paper's "shape text + The person demonstrates a motion like: caption", the target
``[BETA] [SOM] codes [EOM]``; with ``m2t_share`` > 0 some examples are the reverse task
(motion tokens in, caption out), the paper's motion-to-text pre-training (T5 encoder only).
For the MiniLM encoder the shape text and the caption are encoded as two segments
(``minilm_inputs``), each from the frozen encoder's cached states.
"""
from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import torch

from ..data.actions import stored_labels
from ..data.paraphrase_bank import BANK_SHARE, training_caption
from ..errors import ShapeMoveError
from ..models.shapemove_t5 import NULL_PROMPT, shapemove_prompt
from ..models.tokenizer import EOM, SOM
from .action_balance import clip_weights
from .motion_dataset import read_split


def read_lines(path: Path) -> list[str]:
    return [ln.strip() for ln in Path(path).read_text(encoding="utf-8").splitlines() if ln.strip()] if Path(path).is_file() else []


@torch.no_grad()
def tokenize_clips(vae, root: Path, ids: list[str], progress=None) -> dict[str, np.ndarray]:
    """FSQ indices (N,) of each clip's normalized motion (cropped to a multiple of 4 frames): the
    base codes, which the T5 learns (a residual code is left out)."""
    vae.eval()
    down = vae.cfg.downsample
    out = {}
    for i, cid in enumerate(ids):
        f = np.load(Path(root) / "norm_joint_vecs" / f"{cid}.npy")
        n = (len(f) // down) * down
        if n < down:
            continue
        x = vae.normalize(torch.as_tensor(f[:n], dtype=torch.float32)[None])
        out[cid] = vae.encode(x)[1][0].numpy().astype(np.int16)
        if progress:
            progress((i + 1) / len(ids), cid)
    return out


def all_texts(root: Path, ids: list[str]) -> list[str]:
    """Every caption and shape text of the clips (the tokenizer's training corpus)."""
    texts = []
    for cid in ids:
        texts += read_lines(Path(root) / "texts" / f"{cid}.txt")
        texts += read_lines(Path(root) / "shape_texts" / f"{cid}.txt")
    return texts


def body_words(meta: dict, betas: np.ndarray, key: str, n: int = 3) -> list[str]:
    """Shape texts of a clip's body in phenotype words (``phenotype_captions``): from the phenotype
    it was drawn from (augmented copies), else the OpenBody phenotype read back from its betas."""
    from ..body.load import load_body_model
    from ..data.phenotype_captions import phenotype_texts

    pmap = getattr(load_body_model(None), "phenotype_map", None)
    pheno = meta.get("phenotype")
    if pheno is None:
        if pmap is None:
            return []
        pheno = dict(zip(pmap.names, pmap.from_betas(betas)))
    return phenotype_texts(pheno, meta.get("measure") or {}, key, n)


class T2MExamples:
    def __init__(self, root: Path, split: str, tokens: dict[str, np.ndarray], max_codes: int = 50,
                 m2t_share: float = 0.0, no_shape_share: float = 0.2, bank_share: float = BANK_SHARE,
                 action_balance: float = 0.0, null_share: float = 0.0):
        root = Path(root)
        self.ids = [c for c in read_split(root, split) if c in tokens and len(tokens[c])]
        if not self.ids:
            raise ShapeMoveError(f"{root}: no tokenized clips in split '{split}'")
        self.tokens = tokens
        self.captions = {c: read_lines(root / "texts" / f"{c}.txt") or ["a person moves."] for c in self.ids}
        self.labels = {c: stored_labels(root, c) for c in self.ids}
        self.shapes = {c: read_lines(root / "shape_texts" / f"{c}.txt") for c in self.ids}
        self.betas = {c: np.load(root / "betas" / f"{c}.npy").astype(np.float32) for c in self.ids}
        self.max_codes, self.m2t_share, self.no_shape_share = max_codes, m2t_share, no_shape_share
        self.bank_share = bank_share
        self.null_share = null_share  # share of examples whose motion text is NULL_PROMPT (guidance)
        self.cumulative = clip_weights(self.ids, self.labels, action_balance).cumsum()
        from ..data.built_meta import clip_meta
        from ..models.motion_memory import family

        self.family = {c: family(c, clip_meta(root, c)) for c in self.ids}  # left out of its own retrieval
        for c in self.ids:  # the body also in the words people use (man/woman, age, build, weight)
            self.shapes[c] = self.shapes[c] + body_words(clip_meta(root, c), self.betas[c], c)

    def __len__(self) -> int:
        return len(self.ids)

    def sample(self, rng: random.Random) -> dict:
        i = int(np.searchsorted(self.cumulative, rng.random() * self.cumulative[-1], side="right"))
        cid = self.ids[min(i, len(self.ids) - 1)]
        codes = self.tokens[cid]
        if len(codes) > self.max_codes:
            s = rng.randrange(len(codes) - self.max_codes + 1)
            codes = codes[s: s + self.max_codes]
        caption = training_caption(self.captions[cid], self.labels[cid], rng, self.bank_share)
        if self.null_share and rng.random() < self.null_share:  # no draw at 0: the same examples as before
            caption = NULL_PROMPT
        if self.m2t_share and rng.random() < self.m2t_share:
            motion = SOM + "".join(f"[MID_{int(c)}]" for c in codes) + EOM
            return {"input": f"Describe the motion: {motion}", "codes": None, "text": caption, "betas": None,
                    "key": caption}
        shapes = self.shapes[cid]
        shape = None if (not shapes or rng.random() < self.no_shape_share) else rng.choice(shapes)
        return {"input": shapemove_prompt(caption, shape), "codes": codes.tolist(), "text": None,
                "betas": self.betas[cid], "key": caption, "motion_text": caption, "shape_text": shape,
                "family": self.family[cid]}


def collate(examples: list[dict], tok, vocab, max_input: int = 160):
    """T5 encoder: (input_ids, attention_mask, labels, betas)."""
    enc = tok([e["input"] for e in examples], return_tensors="pt", padding=True, truncation=True, max_length=max_input)
    labels, betas = _targets(examples, tok, vocab)
    return enc.input_ids, enc.attention_mask, labels, betas


def collate_minilm(examples: list[dict], states, vocab, model=None, rng: random.Random | None = None):
    """MiniLM encoder: ((states, mask, segments), labels, betas, memory); ``states``: a StateCache;
    ``memory``: for a ``model`` that reads retrieved clips, those of each example's caption (its own
    clip's family left out, ``rng`` choosing among clips that share a caption), else None."""
    from ..models.shapemove_t5 import minilm_inputs

    if any(e["codes"] is None for e in examples):
        raise ShapeMoveError("motion-to-text examples need the T5 encoder (set m2t_share to 0 for MiniLM)")
    inputs = minilm_inputs(states, [e["motion_text"] for e in examples], [e["shape_text"] for e in examples])
    labels, betas = _targets(examples, None, vocab)
    memory = None
    if model is not None and model.memory_k:
        memory = model.memory_inputs(states, [e["motion_text"] for e in examples],
                                     exclude=[e.get("family", frozenset()) for e in examples], rng=rng)
    return inputs, labels, betas, memory


def _targets(examples: list[dict], tok, vocab):
    targets = []
    for e in examples:
        if e["codes"] is not None:
            targets.append(vocab.target_ids(e["codes"]))
        else:
            targets.append(tok(e["text"], truncation=True, max_length=64).input_ids)
    L = max(len(t) for t in targets)
    labels = torch.full((len(targets), L), -100, dtype=torch.long)
    for i, t in enumerate(targets):
        labels[i, : len(t)] = torch.tensor(t)
    betas = torch.stack([torch.as_tensor(e["betas"]) if e["betas"] is not None else torch.zeros(10) for e in examples])
    return labels, betas
