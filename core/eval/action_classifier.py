"""Which action is a motion? Its k nearest training clips in TMA motion space vote.

    clf = ActionClassifier.from_data(tma, "data/built", actions)   # embeds the train split once
    clf.classify([features, ...])          # -> ["walk", ...]  (raw (T, 263) HumanML3D features)
    clf.ceiling("data/built", "test")      # how often it names real held-out clips' action

Each training clip whose main action (``labels.actions[0]`` of its meta) is one of ``actions`` is
embedded once with the TMA's motion side (unit vectors); clips without one are skipped. A motion is
embedded the same way and gets the majority action of its ``k`` most cosine-similar training clips;
a tie between actions goes to the one whose tied neighbours have the larger summed similarity.
This reads actions in motion space, where they separate well; the TMA's text prototypes of an
action ("A person {phrase}.") lie far from most motions of that action, so nearest-prototype
classification of motions is much weaker (``paraphrase_eval`` still reports it, by name).

``ceiling`` is the classifier's own accuracy on the real clips of another split: strict (the clip's
main action) and lenient (any of its ``labels.actions``), overall and per action. Held-out test
clips are mostly of the frequent actions, so ``reachable`` also asks, per action, how often a NEW
performance of it is named right: each training clip classified among the other training clips
without its captured take (``motion_memory.take_of``: ``X``, its mirror image ``X_mirror`` and
shape-augmented copies ``X_aug``), as a copied real clip is judged (``classify_references``) and as
a generated motion is judged without the retrieved clips it kept. Actions with one to five takes
are rarely reachable by a 5-NN vote however good the generator is.

Composed "A, then B" clips (``labels.sequence``) are left out of the reference set: they hold two
actions, so neither label describes them.

``FeatureEmbedder`` is a second embedding that does not use the TMA at all (the normalized raw
features, mean/std over the clip and the means of its four quarters): generation picks among
samples with the TMA (``generation/rerank.py``), so a TMA-only judge could flatter it.
"""
from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError

REPO_ROOT = Path(__file__).resolve().parents[2]
FEATURES = "new_joint_vecs"
MAX_CLIP_FRAMES = 20 * 60 * 10  # 10 minutes at 20 fps: longer is not a clip of a built dataset
CHUNK = 256  # clips loaded and embedded at a time (bounded memory)


def default_built_dir() -> Path | None:
    """``$SHAPEMOVE_BUILT``, else the repository's ``data/built`` (``make train-default``), if it exists."""
    env = os.environ.get("SHAPEMOVE_BUILT")
    p = Path(env) if env else REPO_ROOT / "data" / "built"
    return p if p.is_dir() else None



def built_dir(data, why: str) -> Path:
    """``data``, else ``default_built_dir()``; neither: a ShapeMoveError saying ``why`` the built dataset
    is needed and how to name it."""
    data = data if data is not None else default_built_dir()
    if data is None:
        raise ShapeMoveError(f"{why}: pass --data BUILT, the built dataset the model was trained on "
                             "(or set SHAPEMOVE_BUILT; default data/built when it exists)")
    return data

def check_built(data) -> Path:
    data = Path(data)
    if not data.is_dir():
        raise ShapeMoveError(f"dataset folder not found: {data} (build one with `python -m shapemove data build`)")
    if not (data / FEATURES).is_dir():
        raise ShapeMoveError(f"{data}: not a built dataset (no {FEATURES}/ folder)")
    return data


def clip_actions(data, ids: list[str]) -> dict[str, list[str]]:
    """{clip id: its labels.actions} for the clips ``ids`` (``built_meta.read_meta``: ``meta.jsonl``,
    else ``meta/ID.json``); clips without meta or actions get []."""
    from ..data.built_meta import read_meta

    metas = read_meta(data, ids)
    return {cid: _actions_of(metas[cid]) for cid in ids}


def _actions_of(meta) -> list[str]:
    """labels.actions of a clip's meta; [] for a composed clip ("A, then B": labels.sequence; legs
    of one clip and arms of another: composed_from) and for a mirror image (the judge's references
    are real captured clips as they were captured)."""
    labels = meta.get("labels") if isinstance(meta, dict) else None
    if isinstance(labels, dict) and labels.get("sequence"):
        return []
    if isinstance(meta, dict) and (meta.get("composed_from") or meta.get("mirror_of")):
        return []
    acts = labels.get("actions") if isinstance(labels, dict) else None
    return [a for a in acts if isinstance(a, str)] if isinstance(acts, list) else []


def labelled_clips(data, split: str, actions, max_clips: int | None = None, seed: int = 0):
    """[(clip id, labels.actions)] of ``split`` whose main action is one of ``actions`` (all, or a
    seeded random ``max_clips`` of them, in split order)."""
    from ..train.motion_dataset import read_split

    data = check_built(data)
    ids = read_split(data, split)
    known = set(actions)
    acts = clip_actions(data, ids)
    clips = [(cid, acts[cid]) for cid in ids if acts[cid] and acts[cid][0] in known]
    if max_clips is not None and len(clips) > max_clips:
        keep = np.sort(np.random.default_rng(seed).choice(len(clips), max_clips, replace=False))
        clips = [clips[i] for i in keep]
    return clips


def load_features(data, cid: str) -> np.ndarray | None:
    """The clip's raw (T, 263) features, or None when it has no usable features file."""
    from .tma_embed import FEATURE_DIM

    f = Path(data) / FEATURES / f"{cid}.npy"
    if not f.is_file():
        return None
    try:
        x = np.load(f, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError):
        return None
    if x.ndim != 2 or x.shape[1] != FEATURE_DIM or not 4 <= x.shape[0] <= MAX_CLIP_FRAMES:
        return None
    x = np.asarray(x, dtype=np.float32)
    return x if np.isfinite(x).all() else None


def embed_clips(embed: Callable, data, clips, desc: str, progress: bool = True):
    """(unit embeddings (N, E), [labels.actions] of the embedded clips, ids skipped for lack of
    usable features), loading and embedding ``CHUNK`` clips at a time."""
    from tqdm import tqdm

    embs, labels, skipped = [], [], []
    with tqdm(total=len(clips), desc=desc, unit="clip", disable=not progress) as bar:
        for s in range(0, len(clips), CHUNK):
            feats = []
            for cid, acts in clips[s:s + CHUNK]:
                f = load_features(data, cid)
                if f is None:
                    skipped.append(cid)
                else:
                    feats.append(f)
                    labels.append(acts)
            if feats:
                embs.append(np.asarray(embed(feats), np.float32))
            bar.update(len(clips[s:s + CHUNK]))
    emb = np.concatenate(embs) if embs else np.zeros((0, 0), np.float32)
    return emb, labels, skipped


def knn_vote(sims: np.ndarray, labels: list[str], k: int = 5) -> list[str]:
    """Per row of ``sims`` (N, M: similarity to each of M labelled examples), the majority label of
    its ``k`` most similar examples; ties go to the label with the larger summed similarity."""
    sims = np.asarray(sims, np.float64)
    if sims.ndim != 2 or sims.shape[1] != len(labels) or not len(labels):
        raise ShapeMoveError(f"knn_vote: similarities of shape {sims.shape} for {len(labels)} labelled examples")
    k = max(1, min(int(k), len(labels)))
    top = np.argpartition(-sims, k - 1, axis=1)[:, :k] if k < len(labels) else np.tile(np.arange(len(labels)), (len(sims), 1))
    out = []
    for row, idx in zip(sims, top):
        votes: dict[str, list] = {}
        for j in idx:
            v = votes.setdefault(labels[j], [0, 0.0])
            v[0] += 1
            v[1] += float(row[j])
        out.append(max(sorted(votes), key=lambda a: (votes[a][0], votes[a][1])))
    return out


def score(preds: list[str], label_lists: list[list[str]]) -> dict:
    """Strict (== labels[0]) and lenient (in labels) accuracy, overall and per main action."""
    per: dict = {}
    for p, labels in zip(preds, label_lists):
        d = per.setdefault(labels[0], {"n": 0, "strict": 0, "lenient": 0})
        d["n"] += 1
        d["strict"] += p == labels[0]
        d["lenient"] += p in labels
    n = sum(d["n"] for d in per.values())
    return {"accuracy": sum(d["strict"] for d in per.values()) / n if n else None,
            "accuracy_lenient": sum(d["lenient"] for d in per.values()) / n if n else None,
            "clips": n,
            "per_action": {a: {"n": d["n"], "accuracy": d["strict"] / d["n"], "accuracy_lenient": d["lenient"] / d["n"]}
                           for a, d in sorted(per.items())}}


class FeatureEmbedder:
    """Unit vectors of raw (T, 263) features without any learned model: the features normalized
    with the dataset's Mean/Std, then their mean and std over time and the means of the four
    quarters of the clip (6 x 263 values)."""

    QUARTERS = 4

    def __init__(self, mean, std):
        self.mean = np.asarray(mean, np.float32)
        self.std = np.where(np.asarray(std, np.float32) > 1e-8, np.asarray(std, np.float32), 1.0)

    @classmethod
    def from_data(cls, data) -> "FeatureEmbedder":
        data = check_built(data)
        try:
            mean, std = (np.load(data / f"{n}.npy", allow_pickle=False) for n in ("Mean", "Std"))
        except (OSError, ValueError) as exc:
            raise ShapeMoveError(f"{data}: Mean.npy/Std.npy missing or unreadable ({exc})") from None
        if mean.shape != (263,) or std.shape != (263,):
            raise ShapeMoveError(f"{data}: Mean.npy/Std.npy must hold 263 values, got {mean.shape}/{std.shape}")
        return cls(mean, std)

    def one(self, feats) -> np.ndarray:
        x = (np.asarray(feats, np.float32) - self.mean) / self.std
        T, q = len(x), self.QUARTERS
        parts = [x[T * i // q: max(T * (i + 1) // q, T * i // q + 1)].mean(0) for i in range(q)]
        v = np.concatenate([x.mean(0), x.std(0), *parts])
        return v / max(float(np.linalg.norm(v)), 1e-8)

    def __call__(self, feats: list) -> np.ndarray:
        return np.stack([self.one(f) for f in feats]) if len(feats) else np.zeros((0, 6 * 263), np.float32)


def tma_embedder(tma) -> Callable:
    """features list -> (N, E) unit TMA motion embeddings, for a ``load_tma`` tuple or a path."""
    from .tma_embed import embed_motions, load_tma

    model, _, mean, std = load_tma(tma) if isinstance(tma, (str, Path)) else tma
    return lambda feats: embed_motions(model, feats, mean, std)


class ActionClassifier:
    """k-nearest-neighbour action of motions among labelled training clips (module docstring)."""

    def __init__(self, embeddings: np.ndarray, labels: list[str], embed: Callable | None = None, k: int = 5,
                 info: dict | None = None, actions=None, sources: list[str] | None = None):
        emb = np.asarray(embeddings, np.float32)
        if emb.ndim != 2 or len(emb) != len(labels) or not len(labels):
            raise ShapeMoveError(f"ActionClassifier: {len(labels)} labels for embeddings of shape {emb.shape}; need >= 1 of each, equal")
        self.embeddings = emb / np.linalg.norm(emb, axis=1, keepdims=True).clip(1e-8)
        self.labels, self.embed, self.k = list(labels), embed, int(k)
        self.info = dict(info or {})
        self.actions = sorted(set(actions) if actions is not None else set(self.labels))
        self.sources = list(sources) if sources is not None else [str(i) for i in range(len(self.labels))]

    @classmethod
    def from_data(cls, tma, data, actions, split: str = "train", k: int = 5, embed: Callable | None = None,
                  progress: bool = True) -> "ActionClassifier":
        """Embed the ``split`` clips of the built dataset ``data`` whose main action is in ``actions``.
        ``embed`` (features list -> (N, E)) replaces the TMA's motion side when given (``tma`` unused)."""
        embed = embed or tma_embedder(tma)
        data = check_built(data)
        clips = labelled_clips(data, split, actions)
        if not clips:
            raise ShapeMoveError(f"{data}: no clip of split '{split}' ({split}.txt) has a main action "
                                 "(labels.actions[0] of its meta) among the model's known actions; "
                                 "is this the built dataset the model was trained on?")
        emb, labels, skipped = embed_clips(embed, data, clips, f"embed {split} clips", progress)
        if not labels:
            raise ShapeMoveError(f"{data}: none of the {len(clips)} labelled '{split}' clips has usable "
                                 f"{FEATURES}/ features")
        main = [a[0] for a in labels]
        gone = set(skipped)
        from ..models.motion_memory import take_of

        sources = [take_of(cid) for cid, _ in clips if cid not in gone]
        ids = [cid for cid, _ in clips if cid not in gone]
        info = {"kind": f"{k}-nearest training clips in TMA motion space", "k": k, "data": str(data),
                "split": split, "clips": len(main), "skipped_without_features": len(skipped),
                "actions_without_clips": sorted(set(actions) - set(main))}
        out = cls(emb, main, embed, k, info, actions, sources)
        out.ids = ids  # the reference clips' ids (their captions: the nearest-caption baseline)
        return out

    @classmethod
    def from_features(cls, data, actions, split: str = "train", progress: bool = True) -> "ActionClassifier":
        """The judge without a learned model: ``from_data`` on ``FeatureEmbedder`` vectors of the raw
        features (the dataset's Mean/Std), so a choice made by the TMA cannot flatter it."""
        out = cls.from_data(None, data, actions, split, embed=FeatureEmbedder.from_data(data), progress=progress)
        out.info["kind"] = f"{out.k}-nearest training clips in pooled raw-feature space (no TMA)"
        return out

    def classify_embeddings(self, emb: np.ndarray, chunk: int = 1024, exclude: list | None = None) -> list[str]:
        """Action of each embedding. ``exclude[i]``: a clip id or clip ids whose captured takes (each clip, its
        mirror image and shape-augmented copies) row i must not find among the references (a
        motion made of retrieved training clips, judged without them), or None / empty."""
        from ..models.motion_memory import take_of

        emb = np.asarray(emb, np.float32)
        if emb.ndim != 2 or emb.shape[1] != self.embeddings.shape[1]:
            raise ShapeMoveError(f"ActionClassifier: embeddings of shape {emb.shape}, expected (N, {self.embeddings.shape[1]})")
        emb = emb / np.linalg.norm(emb, axis=1, keepdims=True).clip(1e-8)
        roots = np.asarray([take_of(c) for c in self.sources]) if exclude is not None else None
        out: list[str] = []
        for s in range(0, len(emb), chunk):  # (chunk, M) similarities at a time
            sims = emb[s:s + chunk] @ self.embeddings.T
            if roots is not None:
                for i, cids in enumerate(exclude[s:s + chunk]):
                    if cids:  # one clip id, or several
                        cids = [cids] if isinstance(cids, str) else cids
                        sims[i, np.isin(roots, [take_of(c) for c in cids])] = -1e9
            out += knn_vote(sims, self.labels, self.k)
        return out

    def reachable(self, chunk: int = 512) -> dict:
        """Per action, the share of its reference clips named right when each is classified among
        the others without its own take (the clip, its mirror image and augmented copies): how often
        a new performance of the action can be judged right. {action: {"n", "accuracy"}}."""
        src = np.asarray(self.sources)
        preds: list[str] = []
        for s in range(0, len(self.labels), chunk):
            sims = self.embeddings[s:s + chunk] @ self.embeddings.T
            sims[src[s:s + chunk, None] == src[None, :]] = -np.inf
            preds += knn_vote(np.where(np.isfinite(sims), sims, -1e9), self.labels, self.k)
        out: dict = {}
        for p, a in zip(preds, self.labels):
            d = out.setdefault(a, {"n": 0, "right": 0})
            d["n"] += 1
            d["right"] += p == a
        return {a: {"n": d["n"], "accuracy": d["right"] / d["n"]} for a, d in sorted(out.items())}

    def classify_references(self, index: list[int]) -> list[str]:
        """Action of reference clips ``index`` each judged among the others without its own take
        (as ``reachable`` does): how a copied real clip is judged, without finding itself."""
        src = np.asarray(self.sources)
        if not len(index):
            return []
        sims = self.embeddings[index] @ self.embeddings.T
        sims[src[index][:, None] == src[None, :]] = -np.inf
        return knn_vote(np.where(np.isfinite(sims), sims, -1e9), self.labels, self.k)

    def classify(self, feats: list, exclude: list | None = None) -> list[str]:
        """Action of each raw (T, 263) feature array (``exclude``: as ``classify_embeddings``)."""
        if self.embed is None:
            raise ShapeMoveError("ActionClassifier: built from embeddings only; it cannot embed motions")
        return self.classify_embeddings(self.embed(feats), exclude=exclude) if len(feats) else []

    def ceiling(self, data, split: str = "test", max_clips: int | None = None, seed: int = 0,
                progress: bool = True) -> dict:
        """``score`` of the classifier on the real clips of ``split`` whose main action
        (``labels.actions[0]``) is one of ``self.actions`` (the model's known actions, also those
        without training clips, which it can never name), plus "split" and "skipped_without_features"."""
        if self.embed is None:
            raise ShapeMoveError("ActionClassifier: built from embeddings only; it cannot embed real clips")
        data = check_built(data)
        clips = labelled_clips(data, split, self.actions, max_clips, seed)
        if not clips:
            return {**score([], []), "split": split, "skipped_without_features": 0}
        emb, labels, skipped = embed_clips(self.embed, data, clips, f"classify {split} clips", progress)
        preds = self.classify_embeddings(emb) if labels else []
        return {**score(preds, labels), "split": split, "skipped_without_features": len(skipped)}
