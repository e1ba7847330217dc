"""Training batches cut on the device from clips held in its memory (``train.resident``).

A GPU steps through a small SA-VAE faster than worker processes can read crops from disk, so a
run on one holds every training clip there once (normalized canonical and shape-aware features,
contacts, betas: a few GB for the whole dataset) and cuts each batch by indexing. The draw is
``MotionClips``': clips in proportion to ``weights`` (``action_balance``), crop starts by the
clip's ``start_cdf`` (``crop_starts``) or uniformly; it is a pure function of (seed, step), so a
resumed run sees the batches an uninterrupted one would.
"""
from __future__ import annotations

import numpy as np
import torch

from .motion_dataset import CONTACT_ORDER, MotionClips


class ResidentBatches:
    """Endless batches (dicts of device tensors: x, y (B, window, D), betas (B, 10), contacts
    (B, window, 4) when the dataset has them, and with ``body_of`` the target bones and soles of
    each clip's body) for one process, from step ``start_step`` on."""

    def __init__(self, dataset: MotionClips, batch: int, seed: int = 0, start_step: int = 0, weights=None,
                 device="cpu", rank: int = 0, body_of=None):
        self.batch, self.seed, self.start_step, self.rank = batch, seed, start_step, rank
        self.window, self.device = dataset.window, torch.device(device)
        n = len(dataset)
        w = np.ones(n) if weights is None else np.asarray(weights, np.float64)
        self.p = torch.as_tensor(w / w.sum(), dtype=torch.float64)
        xs, ys, cs = [], [], []
        for cid in dataset.ids:
            xs.append((dataset._load("norm_joint_vecs", cid) - dataset.mean) / dataset.std)
            ys.append((dataset._load("new_joint_vecs", cid) - dataset.mean) / dataset.std)
            if dataset.has_contacts:
                cs.append(dataset._load("contacts", cid)[:len(xs[-1]), CONTACT_ORDER])   # a row a feature row:
                # the contacts hold one more frame than the features (a clip's last), which would
                # shift every later clip's contacts by a frame more
        lengths = np.array([len(a) for a in xs])
        self.offsets = torch.as_tensor(np.concatenate([[0], np.cumsum(lengths)[:-1]]), dtype=torch.long)
        # possible starts per clip; a clip shorter than the window (``MotionClips.min_frames``) has one
        self.starts = torch.as_tensor(np.maximum(lengths - self.window + 1, 1), dtype=torch.long)
        self.lengths = torch.as_tensor(lengths, dtype=torch.long)
        self.padded = dataset.padded
        self.x = torch.from_numpy(np.concatenate(xs)).to(self.device)
        self.y = torch.from_numpy(np.concatenate(ys)).to(self.device)
        self.contacts = torch.from_numpy(np.concatenate(cs)).to(self.device) if cs else None
        self.betas = torch.from_numpy(np.stack([dataset._load("betas", c).reshape(-1) for c in dataset.ids])).to(self.device)
        # ``body_of(betas)`` -> (bones, soles) per clip, computed once instead of every batch
        self.body = None
        if body_of is not None:
            parts = [body_of(self.betas[i:i + 4096]) for i in range(0, n, 4096)]
            self.body = tuple(torch.cat([p[k] for p in parts]).to(self.device) for k in range(2))
        # crop starts: one global cumulative weight over every clip's starts (float64, on the CPU)
        if any(c is not None for c in dataset.start_cdf):
            parts = [np.ones(int(s)) if c is None else np.diff(c, prepend=0.0) for c, s in zip(dataset.start_cdf, self.starts)]
            cdf = np.cumsum(np.concatenate(parts))
            self.cdf = torch.as_tensor(cdf, dtype=torch.float64)
            ends = np.cumsum([len(p) for p in parts])
            self.cdf_first = torch.as_tensor(ends - [len(p) for p in parts], dtype=torch.long)
            self.cdf_base = torch.as_tensor(np.concatenate([[0.0], cdf[ends[:-1] - 1]]), dtype=torch.float64)
        else:
            self.cdf = None
        self.frames = torch.arange(self.window)

    def draw(self, step: int) -> tuple[torch.Tensor, torch.Tensor]:
        """(clip indices, crop starts) of ``step``'s batch, (B,) each."""
        g = torch.Generator().manual_seed(int(np.random.SeedSequence([self.seed, self.rank, step]).generate_state(1)[0]))
        clips = torch.multinomial(self.p, self.batch, replacement=True, generator=g)
        u = torch.rand(self.batch, generator=g, dtype=torch.float64)
        if self.cdf is None:
            start = (u * self.starts[clips]).long()
        else:
            first = self.cdf_first[clips]
            total = self.cdf[first + self.starts[clips] - 1] - self.cdf_base[clips]
            pos = torch.searchsorted(self.cdf, self.cdf_base[clips] + u * total, right=True)
            start = pos - first
        return clips, torch.minimum(start.clamp_min(0), self.starts[clips] - 1)

    def __iter__(self):
        step = self.start_step
        while True:
            clips, start = self.draw(step)
            rows = ((self.offsets[clips] + start)[:, None] + self.frames).clamp(max=len(self.x) - 1).to(self.device)
            b = {"x": self.x[rows], "y": self.y[rows], "betas": self.betas[clips.to(self.device)]}
            if self.contacts is not None:
                b["contacts"] = self.contacts[rows]
            if self.padded:   # past a short clip's end: zeros, not the next clip's frames (``MotionClips``)
                valid = (self.frames[None] < self.lengths[clips][:, None]).to(self.device)
                for k in ("x", "y", "contacts"):
                    if k in b:
                        b[k] = b[k] * valid[..., None].to(b[k])
                b["valid"] = valid.float()
            if self.body is not None:
                c = clips.to(self.device)
                b["bones"], b["soles"] = self.body[0][c], self.body[1][c]
            yield b
            step += 1
