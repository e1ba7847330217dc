"""Training clips of a built dataset folder, served as random crops.

Folder layout (written by ``core/data/build.py``): ``norm_joint_vecs/ID.npy`` (T,263) features of
the motion on the canonical body (encoder input), ``new_joint_vecs/ID.npy`` (T,263) shape-aware
features (decoder target), ``betas/ID.npy`` (10,), ``Mean.npy``/``Std.npy`` (263,),
``train.txt``/``val.txt``/``test.txt`` (one id a line).

Crops are deterministic functions of (seed, epoch, clip index), and batches of (seed, step), so a
resumed run sees exactly the batches an uninterrupted one would, with any number of workers.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from torch.utils.data import Dataset, DistributedSampler

from ..errors import ShapeMoveError
from .crop_starts import start_weights

CONTACT_ORDER = [0, 2, 1, 3]   # stored contacts (joints 7, 8, 10, 11) -> feature channels (7, 10, 8, 11)


def load_stats(root) -> tuple[np.ndarray, np.ndarray]:
    """Mean/Std (263,) float32 of a dataset folder."""
    root = Path(root)
    try:
        mean = np.load(root / "Mean.npy", allow_pickle=False).astype(np.float32)
        std = np.load(root / "Std.npy", allow_pickle=False).astype(np.float32)
    except FileNotFoundError as exc:
        raise ShapeMoveError(f"{root}: Mean.npy/Std.npy missing; is this a built dataset folder? (`data build`)") from exc
    except (OSError, ValueError, EOFError, TypeError) as exc:  # pickled, truncated or not an .npy: never unpickled
        raise ShapeMoveError(f"{root}: Mean.npy/Std.npy cannot be read as plain number arrays ({str(exc)[:120]}); "
                             "rebuild the dataset with `data build`") from None
    if mean.shape != std.shape or mean.ndim != 1 or not (np.isfinite(mean).all() and np.isfinite(std).all()):
        raise ShapeMoveError(f"{root}: Mean.npy/Std.npy must be finite vectors of equal length")
    if (std <= 0).any():
        raise ShapeMoveError(f"{root}: Std.npy has values <= 0")
    return mean, std


def read_split(root, split: str) -> list[str]:
    p = Path(root) / f"{split}.txt"
    return p.read_text().split() if p.is_file() else []


class MotionClips(Dataset):
    """Item ``(index, epoch)`` (or ``index``, epoch 0) -> dict of float32 tensors:
    x (window, D) normalized canonical features, y (window, D) normalized shape-aware features
    (same frames), betas (10,). Clips shorter than ``min_frames`` (0: ``window``) are left out
    (``self.skipped``); with ``min_frames`` under ``window`` a shorter clip is served whole from its
    first frame, zeros after its end (the mean pose: what a convolution reads past the end of a
    clip encoded alone), and every item carries ``valid`` (window,): 1 on the clip's frames, 0 on
    the padding, which no loss counts (``vae_losses``). Left out, the short clips were 38 % of the
    training split: every squat, 16 of 18 kicks, 14 of 16 reaches up, every jog.
    ``active_windows`` > 0 draws crop starts where the pose moves (``crop_starts.start_weights``).
    ``stats``: (mean, std) to normalize with instead of the folder's Mean/Std (a model fine-tuned
    from a checkpoint keeps the normalization it was trained with)."""

    def __init__(self, root, split: str = "train", window: int = 64, seed: int = 0, stats=None,
                 active_windows: float = 0.0, min_frames: int = 0):
        self.root = Path(root)
        if not self.root.is_dir():
            raise ShapeMoveError(f"dataset folder not found: {self.root}")
        self.window, self.seed = window, seed
        self.min_frames = min(window, min_frames) if min_frames > 0 else window
        self.padded = self.min_frames < window     # items carry ``valid``
        self.has_contacts = (self.root / "contacts").is_dir()
        self.mean, self.std = load_stats(self.root)
        if stats is not None:
            mean, std = (np.asarray(a, dtype=np.float32).reshape(-1) for a in stats)
            if mean.shape != self.mean.shape or std.shape != self.std.shape:
                raise ShapeMoveError(f"{self.root}: the model's Mean/Std have {mean.shape[0]} values, the dataset's features {self.mean.shape[0]}")
            self.mean, self.std = mean, std
        self.ids, self.lengths, self.skipped = [], [], []
        self.start_cdf: list = []   # per clip: cumulative crop-start weights (``crop_starts``), None = uniform
        for cid in read_split(self.root, split):
            try:
                x = np.load(self.root / "norm_joint_vecs" / f"{cid}.npy", mmap_mode="r")
                y = np.load(self.root / "new_joint_vecs" / f"{cid}.npy", mmap_mode="r")
            except FileNotFoundError as exc:
                raise ShapeMoveError(f"{self.root}: clip '{cid}' of {split}.txt has no features ({exc.filename})") from exc
            if x.shape != y.shape or x.ndim != 2 or x.shape[1] != self.mean.shape[0]:
                raise ShapeMoveError(f"{self.root}: clip '{cid}': feature shapes {x.shape} / {y.shape} do not match Mean ({self.mean.shape[0]})")
            if x.shape[0] < self.min_frames:
                self.skipped.append(cid)
                continue
            self.ids.append(cid)
            self.lengths.append(int(x.shape[0]))
            whole = x.shape[0] <= window     # served whole: one start
            self.start_cdf.append(np.cumsum(start_weights(x, window, active_windows))
                                  if active_windows > 0 and not whole else None)

    def __len__(self) -> int:
        return len(self.ids)

    def _load(self, sub: str, cid: str, start: int | None = None) -> np.ndarray:
        a = np.load(self.root / sub / f"{cid}.npy", mmap_mode="r")
        return np.array(a if start is None else a[start:start + self.window], dtype=np.float32)

    def __getitem__(self, key) -> dict:
        index, epoch = key if isinstance(key, tuple) else (key, 0)
        cid = self.ids[index]
        rng = np.random.default_rng([self.seed, epoch, index])
        cdf = self.start_cdf[index]
        if cdf is None:
            start = int(rng.integers(0, max(1, self.lengths[index] - self.window + 1)))
        else:
            start = min(int(np.searchsorted(cdf, rng.random() * cdf[-1], side="right")), len(cdf) - 1)
        n = min(self.window, self.lengths[index])    # the clip's frames in the window; zeros after
        x = self._padded((self._load("norm_joint_vecs", cid, start) - self.mean) / self.std)
        y = self._padded((self._load("new_joint_vecs", cid, start) - self.mean) / self.std)
        betas = self._load("betas", cid).reshape(-1)
        item = {"x": torch.from_numpy(x), "y": torch.from_numpy(y), "betas": torch.from_numpy(betas)}
        if self.has_contacts:
            c = self._load("contacts", cid, start)[:n]   # a row a frame; the features lack the last frame
            if c.shape != (n, 4):
                raise ShapeMoveError(f"{self.root}: clip '{cid}': contacts/{cid}.npy must be (frames, 4), got {c.shape}")
            item["contacts"] = torch.from_numpy(self._padded(c[:, CONTACT_ORDER]))
        if self.padded:
            item["valid"] = torch.from_numpy((np.arange(self.window) < n).astype(np.float32))
        return item

    def _padded(self, a: np.ndarray) -> np.ndarray:
        """(n, C) rows -> (window, C): zeros after the clip's end."""
        if len(a) == self.window:
            return np.ascontiguousarray(a, dtype=np.float32)
        out = np.zeros((self.window, a.shape[1]), np.float32)
        out[:len(a)] = a
        return out


class BatchStream:
    """Endless batches of dataset keys ``(index, epoch)`` for one process, starting at ``start_step``.

    Epoch e is ``DistributedSampler(shuffle, seed).set_epoch(e)`` over the clips (each rank gets
    its share); batches run across epoch boundaries, so step s always holds items
    [s*batch, (s+1)*batch) of this rank's stream, whatever step training (re)started at. With
    ``weights`` (one per clip, ``action_balance.clip_weights``: an action's share of training not
    following its clip count) epoch e is as many clips drawn with replacement in proportion to
    them, from a generator seeded by (seed, e), each rank taking every ``world_size``-th."""

    def __init__(self, dataset: MotionClips, batch: int, rank: int = 0, world_size: int = 1, seed: int = 0,
                 start_step: int = 0, weights=None):
        if len(dataset) == 0:
            raise ShapeMoveError(f"{dataset.root}: no clips of at least {dataset.min_frames} frames in this split")
        self.batch, self.start_step = batch, start_step
        self.rank, self.world_size, self.seed = rank, world_size, seed
        self.p, self.sampler = None, None
        if weights is None:
            self.sampler = DistributedSampler(dataset, num_replicas=world_size, rank=rank, shuffle=True, seed=seed)
        else:
            w = np.asarray(weights, dtype=np.float64)
            if w.shape != (len(dataset),) or not np.isfinite(w).all() or (w < 0).any() or w.sum() <= 0:
                raise ShapeMoveError(f"sampling weights must be {len(dataset)} finite values >= 0, not all 0")
            self.p = w / w.sum()

    def _epoch(self, e: int) -> list[int]:
        if self.p is None:
            self.sampler.set_epoch(e)
            return list(self.sampler)
        drawn = np.random.default_rng([self.seed, e]).choice(len(self.p), size=len(self.p), p=self.p)
        return [int(i) for i in drawn[self.rank::self.world_size]]

    def __iter__(self):
        per_epoch = len(self.sampler) if self.p is None else len(range(self.rank, len(self.p), self.world_size))
        j = self.start_step * self.batch
        epoch, order = -1, []
        while True:
            keys = []
            for _ in range(self.batch):
                e, pos = divmod(j, per_epoch)
                if e != epoch:
                    epoch, order = e, self._epoch(e)
                keys.append((order[pos], e))
                j += 1
            yield keys
