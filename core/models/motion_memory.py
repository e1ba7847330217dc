"""Retrieval as memory: the motion tokens of the real clips whose captions are nearest to a prompt,
which ShapeMove's T5 decoder reads beside the text (retrieval-augmented generation, as in
ReMoDiffuse / ReMoMask, which gain most on small datasets and uncommon motions).

A ``MotionMemory`` holds distinct caption texts with their unit MiniLM sentence vectors (the mean of
the frozen encoder's token states, as ``known_texts`` computes them), for each text the clips that
carry it, and each clip's FSQ tokens. ``lookup`` takes prompts and returns, for each, the tokens
of ``k`` clips in order of their caption's cosine similarity to the prompt, with that similarity:

    mem = MotionMemory.from_dataset(data, train_ids, tokens, states)    # training
    ids, sims = mem.lookup(states, ["a man throws a jab"], k=3)          # (1, 3, L) codes, (1, 3)

During training a clip must not find itself: ``lookup`` takes, per prompt, a set of clip
*families* to leave out (``family``: a clip, its mirror and shape-augmented copies, and every
composed clip made from it share a root id). At generation the memory is the training set shipped
in the model folder (``motion_memory.safetensors`` + ``.json``), plus any user library added with
``add_clips`` (their own motions and captions: no retraining).
"""
from __future__ import annotations

import json
import random
from pathlib import Path

import numpy as np
import torch

from ..constants import NUM_CODES
from ..errors import ShapeMoveError
from .motion_codes import base_of

MEMORY_JSON, MEMORY_TENSORS = "motion_memory.json", "motion_memory.safetensors"
TOP_TEXTS = 64          # nearest distinct captions searched for k clips outside the prompt's families
MAX_MEMORY_BYTES = 64 << 20


def family(cid: str, meta: dict | None = None) -> frozenset:
    """Root ids a clip derives from: its own id without the mirror/augmentation suffixes, and those
    of the clips it was composed from."""
    meta = meta or {}
    parts = [take_of(c) for c in meta.get("composed_from") or []]
    base = meta.get("mirror_of") or cid
    return frozenset([take_of(base)] + parts)


def take_of(cid: str) -> str:
    """The captured take a built clip shows: ``X``, ``X_aug`` and ``X_mirror`` are all ``X``."""
    while cid.endswith(("_mirror", "_aug")):
        cid = cid.rsplit("_", 1)[0]
    return cid


def _caption_actions(captions) -> list[str]:
    """The actions a clip's captions name (``data/actions.py`` patterns), first named first: the
    actions of a clip without labels (a user's library)."""
    from ..data.actions import action_spans

    return list(dict.fromkeys(a for t in captions for _, _, a in action_spans(str(t))))


def sentence_vectors(reader, texts: list[str], batch: int = 256) -> torch.Tensor:
    """(N, 384) unit MiniLM sentence vectors (mean of token states) of ``texts``; ``reader`` is a
    TextEncoder or a StateCache."""
    from .text_encoder import HIDDEN, mean_pool

    out = []
    for s in range(0, len(texts), batch):
        x, m = reader.states(list(texts[s:s + batch]))
        out.append(torch.nn.functional.normalize(mean_pool(x, m), dim=-1))
    return torch.cat(out) if out else torch.zeros(0, HIDDEN)


class MotionMemory:
    def __init__(self, texts: list[str], vectors: torch.Tensor, text_clips: list[list[int]], clip_ids: list[str],
                 clip_tokens: list[np.ndarray], clip_family: list[frozenset] | None = None,
                 clip_actions: list[list[str]] | None = None):
        if not (len(texts) == len(vectors) == len(text_clips)) or len(clip_ids) != len(clip_tokens):
            raise ShapeMoveError("motion memory: texts, vectors and clip lists do not match")
        self.texts, self.vectors = list(texts), vectors.float()
        self.text_clips = [list(c) for c in text_clips]
        self.clip_ids, self.clip_tokens = list(clip_ids), [np.asarray(t, dtype=np.int64) for t in clip_tokens]
        self._clip_index = {c: i for i, c in enumerate(self.clip_ids)}   # clip id -> index (``main_action``)
        self.clip_family = clip_family or [frozenset([c]) for c in clip_ids]
        self._index = {t: i for i, t in enumerate(self.texts)}
        if clip_actions is None or len(clip_actions) != len(self.clip_ids):
            clip_actions = [_caption_actions(self.texts[t] for t in ts) for ts in self._clip_texts()]
        self.clip_actions = [[str(a) for a in acts] for acts in clip_actions]   # labelled actions, main one first

    def __len__(self) -> int:
        return len(self.clip_ids)

    @classmethod
    def empty(cls) -> "MotionMemory":
        """A memory with no clips (a user's library is added to it)."""
        from .text_encoder import HIDDEN

        return cls([], torch.zeros(0, HIDDEN), [], [], [])

    # -- building -------------------------------------------------------------------------------
    @classmethod
    def from_dataset(cls, root, ids: list[str], tokens: dict, reader) -> "MotionMemory":
        """The memory of clips ``ids`` of built dataset ``root`` (their stored captions) with their
        FSQ ``tokens`` (clip id -> codes)."""
        from ..data.built_meta import clip_meta

        root = Path(root)
        mem = cls.empty()
        clips, captions, fams, acts = [], [], [], []
        for cid in ids:
            if cid not in tokens or not len(tokens[cid]):
                continue
            path = root / "texts" / f"{cid}.txt"
            caps = [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()] \
                if path.is_file() else []
            if caps:
                meta = clip_meta(root, cid)
                clips.append(cid)
                captions.append(caps)
                fams.append(family(cid, meta))
                labels = meta.get("labels") if isinstance(meta.get("labels"), dict) else {}
                named = [a for a in labels.get("actions") or [] if isinstance(a, str)]
                acts.append(named if named and not labels.get("sequence") else _caption_actions(caps))
        mem.add_clips(clips, captions, [tokens[c] for c in clips], reader, fams, acts)
        return mem

    def add_clips(self, clip_ids: list[str], captions: list[list[str]], clip_tokens: list, reader,
                  families: list[frozenset] | None = None, actions: list[list[str]] | None = None) -> None:
        """Add clips (a user's library, or the training set) with their captions and FSQ tokens;
        ``actions``: each clip's labelled actions, main one first (default: those its captions name)."""
        new_texts = []
        for cid, caps, toks in zip(clip_ids, captions, clip_tokens):
            c = len(self.clip_ids)
            self.clip_ids.append(str(cid))
            self._clip_index[str(cid)] = c
            self.clip_tokens.append(np.asarray(toks, dtype=np.int64))
            for t in dict.fromkeys(caps):
                i = self._index.get(t)
                if i is None:
                    i = self._index[t] = len(self.texts)
                    self.texts.append(t)
                    self.text_clips.append([])
                    new_texts.append(t)
                self.text_clips[i].append(c)
        self.clip_family += list(families) if families is not None else [frozenset([c]) for c in clip_ids]
        self.clip_actions += ([[str(a) for a in acts] for acts in actions] if actions is not None
                              else [_caption_actions(c) for c in captions])
        if new_texts:
            self.vectors = torch.cat([self.vectors, sentence_vectors(reader, new_texts)])

    # -- lookup ---------------------------------------------------------------------------------
    def _clip_texts(self) -> list[list[int]]:
        """For each clip, the indices of its captions."""
        out: list[list[int]] = [[] for _ in self.clip_ids]
        for t, clips in enumerate(self.text_clips):
            for c in clips:
                out[c].append(t)
        return out

    def main_action(self, clip_id: str) -> str | None:
        """The main labelled action of the clip ``clip_id`` (its first, ``clip_actions``); None for a
        clip with no label or not in the memory."""
        i = self._clip_index.get(clip_id)
        return self.clip_actions[i][0] if i is not None and self.clip_actions[i] else None

    def clips_of_action(self, action: str) -> list[tuple[int, list[int]]]:
        """(clip index, its caption indices) of the clips whose main labelled action is ``action``;
        when none is, those labelled with it at all ("walk in a circle" is a walk's second label)."""
        texts = self._clip_texts()
        for ok in (lambda acts: acts[:1] == [action], lambda acts: action in acts):
            found = [(c, texts[c]) for c, acts in enumerate(self.clip_actions) if ok(acts) and texts[c]]
            if found:
                return found
        return []

    def nearest(self, vectors: torch.Tensor, k: int, exclude: list | None = None,
                rng: random.Random | None = None) -> list[list[tuple[int, float]]]:
        """For each unit vector (B, 384): up to ``k`` (clip index, similarity), nearest caption
        first, skipping clips whose family meets ``exclude[b]``; among clips sharing a caption
        ``rng`` picks one at random (None: the first)."""
        if not self.texts:
            return [[] for _ in range(len(vectors))]
        sims = vectors.float() @ self.vectors.T
        top = torch.topk(sims, min(TOP_TEXTS, sims.shape[1]), dim=1)
        out = []
        for b in range(len(vectors)):
            fam = exclude[b] if exclude is not None else frozenset()
            chosen: list[tuple[int, float]] = []
            taken = set()
            for s, u in zip(top.values[b].tolist(), top.indices[b].tolist()):
                c = self._pick(self.text_clips[u], taken, fam, rng)
                if c is None:
                    continue
                taken.add(c)
                chosen.append((c, s))
                if len(chosen) == k:
                    break
            out.append(chosen)
        return out

    def nearest_long(self, reader, prompt: str, count: int, min_codes: int, room: int) -> list[tuple[int, float]]:
        """Up to ``count`` (clip index, similarity) of the distinct clips nearest to ``prompt`` by
        caption that have at least ``min_codes`` codes, looked for among the ``room`` nearest
        (generation's retrieved candidates and seeded prefixes)."""
        near = self.nearest(sentence_vectors(reader, [prompt]), room)[0]
        return [(c, s) for c, s in near if len(self.clip_tokens[c]) >= min_codes][:count]

    def nearest_of(self, vector: torch.Tensor, clips, min_codes: int) -> tuple[int, float] | None:
        """(clip index, similarity) of the clip of ``clips`` (indices) whose caption is nearest to the
        unit sentence vector ``vector`` (384,), among those with at least ``min_codes`` codes; None
        when there is none."""
        keep = {int(c) for c in clips if len(self.clip_tokens[int(c)]) >= min_codes}
        if not keep:
            return None
        sims = (self.vectors @ vector.float()).tolist()
        best = None
        for t, cs in enumerate(self.text_clips):
            hit = next((c for c in cs if c in keep), None)
            if hit is not None and (best is None or sims[t] > best[1]):
                best = (hit, sims[t])
        return best

    def _pick(self, clips: list[int], taken: set, fam: frozenset, rng: random.Random | None) -> int | None:
        """A clip of ``clips`` not taken and outside ``fam``: with ``rng`` a few random draws (a
        caption may be shared by hundreds of clips), else the first."""
        ok = lambda c: c not in taken and not (self.clip_family[c] & fam)  # noqa: E731
        if rng is not None and len(clips) > 8:
            for _ in range(8):
                c = clips[rng.randrange(len(clips))]
                if ok(c):
                    return c
        order = clips if rng is None else rng.sample(clips, len(clips))
        return next((c for c in order if ok(c)), None)

    def lookup(self, reader, texts: list[str], k: int, max_codes: int, vocab_offset: int = 0,
               exclude: list | None = None, rng: random.Random | None = None, empty: list[bool] | None = None,
               codebook: int = NUM_CODES):
        """(ids (B, k, max_codes) long: vocab ids ``vocab_offset + code``, -1 where empty; sims (B, k)).
        ``empty[b]``: give prompt b no memory (the null prompt of guidance, memory dropout); the
        codes are the clips' base codes (``codebook``: the T5's number of motion codes)."""
        ids = torch.full((len(texts), k, max_codes), -1, dtype=torch.long)
        sims = torch.zeros(len(texts), k)
        todo = [b for b in range(len(texts)) if not (empty and empty[b]) and str(texts[b]).strip()]
        if not todo or k <= 0:
            return ids, sims
        row = {t: i for i, t in enumerate(dict.fromkeys(texts[b] for b in todo))}  # best-of-N repeats a prompt N times
        vec = sentence_vectors(reader, list(row))[[row[texts[b]] for b in todo]]
        found = self.nearest(vec, k, [exclude[b] for b in todo] if exclude is not None else None, rng)
        for b, near in zip(todo, found):
            for j, (c, s) in enumerate(near):
                codes = base_of(self.clip_tokens[c][:max_codes], codebook)  # the T5 reads base codes
                ids[b, j, : len(codes)] = torch.as_tensor(codes) + vocab_offset
                sims[b, j] = s
        return ids, sims

    # -- persistence ----------------------------------------------------------------------------
    def save(self, folder) -> None:
        from safetensors.torch import save_file

        folder = Path(folder)
        lens = np.array([len(t) for t in self.clip_tokens], dtype=np.int64)
        text_lens = np.array([len(c) for c in self.text_clips], dtype=np.int64)
        flat_clips = np.concatenate([np.asarray(c, np.int64) for c in self.text_clips]) if self.text_clips else np.zeros(0, np.int64)
        flat_tokens = np.concatenate(self.clip_tokens) if self.clip_tokens else np.zeros(0, np.int64)
        (folder / MEMORY_JSON).write_text(json.dumps({"texts": self.texts, "clip_ids": self.clip_ids,
                                                      "clip_actions": self.clip_actions}))
        save_file({"vectors": self.vectors.to(torch.float16).contiguous(),
                   "token_lengths": torch.as_tensor(lens), "tokens": torch.as_tensor(flat_tokens.astype(np.int32)),
                   "text_lengths": torch.as_tensor(text_lens), "text_clips": torch.as_tensor(flat_clips.astype(np.int32))},
                  str(folder / MEMORY_TENSORS))

    @classmethod
    def load(cls, folder) -> "MotionMemory | None":
        """The memory stored in a model folder, or None when it has none (models before it)."""
        from safetensors.torch import load_file

        from ..io.limits import read_json

        folder = Path(folder)
        j, t = folder / MEMORY_JSON, folder / MEMORY_TENSORS
        if not j.is_file() and not t.is_file():
            return None
        if not (j.is_file() and t.is_file()):
            missing = t if j.is_file() else j
            raise ShapeMoveError(f"{folder}: {missing.name} is missing (the retrieval memory needs both "
                                 f"{MEMORY_JSON} and {MEMORY_TENSORS}); copy the model folder again")
        doc = read_json(j, MEMORY_JSON, MAX_MEMORY_BYTES, "copy the model folder again")
        try:
            d = load_file(str(t))
            texts, clip_ids = [str(x) for x in doc["texts"]], [str(x) for x in doc["clip_ids"]]
            lens, tlens = d["token_lengths"].long(), d["text_lengths"].long()
            tokens, tclips = d["tokens"].long().numpy(), d["text_clips"].long().numpy()
            vectors = d["vectors"].float()
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ShapeMoveError(f"{folder}: damaged {MEMORY_TENSORS} ({exc}); copy the model folder again") from None
        if (len(lens) != len(clip_ids) or len(tlens) != len(texts) or len(vectors) != len(texts)
                or int(lens.sum()) != len(tokens) or int(tlens.sum()) != len(tclips)
                or (len(tclips) and (tclips.min() < 0 or tclips.max() >= len(clip_ids)))):
            raise ShapeMoveError(f"{folder}: {MEMORY_JSON} and {MEMORY_TENSORS} do not match; copy the model folder again")
        cut = np.cumsum(lens.numpy())[:-1]
        tcut = np.cumsum(tlens.numpy())[:-1]
        acts = doc.get("clip_actions") if isinstance(doc, dict) else None
        acts = [[str(a) for a in x] for x in acts] if (isinstance(acts, list) and len(acts) == len(clip_ids)
                                                        and all(isinstance(x, list) for x in acts)) else None
        return cls(texts, vectors, [list(x) for x in np.split(tclips, tcut)] if len(texts) else [],
                   clip_ids, list(np.split(tokens, cut)) if len(clip_ids) else [], clip_actions=acts)
