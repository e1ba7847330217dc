"""What a trained model knows: its training captions and actions, with their MiniLM sentence vectors,
stored in the model folder so that generation can tell a user when a prompt is far from all of them.

    known = build_known(data_dir, train_ids, states_cache)   # at training time
    write_known(model_folder, known)                         # known_texts.json + .safetensors
    k = read_known(model_folder)                             # None for folders without it
    report = k.check("a person does a cartwheel", text_encoder)
    report.warning  # "nothing like 'a person does a cartwheel' in the training data; closest known actions: roll, jump"

A prompt is "known" when its MiniLM cosine similarity to the nearest known caption (training
captions plus 40 paraphrase-bank sentences per action) reaches ``NEAR``. Sentence similarity
separates in- and out-of-data prompts only roughly. Measured with the default model on the first
held-out paraphrase set (configs/heldout_paraphrases.json, 141 prompts) and 20 prompts of activities
the data does not hold (violin, cooking, kites, cycling, tennis, ...): at 0.40, 0.7 % of paraphrases
and 25 % of the foreign prompts are warned; at 0.50, 2.1 % and 65 %; at 0.55, 11 % and 85 %. ``NEAR``
= 0.50; the blind held-out set (not used to choose it) gets 2.1 % false warnings. The nearest actions
are ranked by the best similarity among each action's captions and are always reported.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import torch

from ..data.actions import find_actions, stored_labels
from ..data.paraphrase_bank import known_sentences
from ..errors import ShapeMoveError
from ..generation.model_bundle import MAX_KNOWN_BYTES
from ..io.limits import read_json

NEAR = 0.50           # below this cosine similarity to every known caption: warn
MAX_KNOWN = 50_000    # captions kept (bounded file size)
JSON_NAME, VECTORS_NAME = "known_texts.json", "known_texts.safetensors"


@dataclass
class PromptCheck:
    similarity: float                 # cosine similarity to the nearest training caption
    nearest_caption: str
    nearest_actions: list[str] = field(default_factory=list)
    warning: str | None = None
    nearest_action: str | None = None   # the nearest caption's own action (None: it names none)


def _read_lines(path: Path) -> list[str]:
    return [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()] if path.is_file() else []


def _clip_actions(root: Path, cid: str) -> list[str]:
    return [str(a) for a in stored_labels(root, cid).get("actions") or [] if isinstance(a, str)]


def build_known(root, ids: list[str], states) -> dict:
    """Distinct captions of the clips ``ids`` with their action (the clip's main action from the
    dataset's meta, else the first action the caption names), plus a fixed sample of the paraphrase
    bank's sentences for each of those actions (``data/paraphrase_bank.py``), and their unit MiniLM vectors (mean
    of the token states that ``states`` gives: a StateCache or the TextEncoder)."""
    from .text_encoder import mean_pool

    root = Path(root)
    captions: dict[str, str] = {}
    counts: dict[str, int] = {}
    for cid in ids:
        acts = _clip_actions(root, cid)
        lines = _read_lines(root / "texts" / f"{cid}.txt")
        for c in lines:
            if len(captions) >= MAX_KNOWN:
                break
            a = acts[0] if acts else next(iter(find_actions(c)), "")
            if c not in captions or (not captions[c] and a):
                captions[c] = a
        for a in set(acts) or {captions.get(c, "") for c in lines} - {""}:
            counts[a] = counts.get(a, 0) + 1
    for a in counts:  # the phrasings training draws from the paraphrase bank, too
        for c in known_sentences(a):
            captions.setdefault(c, a)
    texts = sorted(captions)
    vecs = []
    for s in range(0, len(texts), 256):
        x, m = states.states(texts[s:s + 256])
        vecs.append(torch.nn.functional.normalize(mean_pool(x, m), dim=-1))
    vectors = torch.cat(vecs) if vecs else torch.zeros(0, 384)
    actions = sorted(counts, key=lambda a: (-counts[a], a))
    return {"captions": texts, "caption_actions": [captions[t] for t in texts],
            "actions": [[a, counts[a]] for a in actions], "vectors": vectors}


def write_known(folder, known: dict) -> None:
    from safetensors.torch import save_file

    folder = Path(folder)
    doc = {"captions": known["captions"], "caption_actions": known["caption_actions"], "actions": known["actions"]}
    (folder / JSON_NAME).write_text(json.dumps(doc, indent=1))
    save_file({"vectors": known["vectors"].to(torch.float16).contiguous()}, str(folder / VECTORS_NAME))


class Known:
    def __init__(self, captions: list[str], caption_actions: list[str], actions: list[tuple[str, int]],
                 vectors: torch.Tensor):
        self.captions, self.caption_actions, self.vectors = captions, caption_actions, vectors.float()
        self.actions = [(str(a), int(n)) for a, n in actions]

    @property
    def action_names(self) -> list[str]:
        """The actions of the training data, most frequent first (the panel's suggestions)."""
        return [a for a, _ in self.actions]

    def check(self, prompt: str, encoder, near: float = NEAR) -> PromptCheck:
        """How close ``prompt`` is to what the model was trained on, with a warning when far."""
        v = encoder.embed([prompt])[0]
        sims = self.vectors @ v
        best = int(sims.argmax())
        sim = float(sims[best])
        nearest = self.nearest_actions(sims)
        warning = None
        if encoder.unknown_share(prompt) > 0.5:
            warning = (f"the text encoder cannot read most of {prompt!r} (unknown characters): describe the motion "
                       "in English words")
        elif sim < near:
            close = ", ".join(nearest) if nearest else repr(self.captions[best])
            warning = (f"nothing like {prompt!r} in the training data (closest caption {sim:.2f} similar: "
                       f"{self.captions[best]!r}); closest known actions: {close}")
        return PromptCheck(sim, self.captions[best], nearest, warning, self.caption_actions[best] or None)

    def nearest_actions(self, sims: torch.Tensor, k: int = 3) -> list[str]:
        best: dict[str, float] = {}
        for i in torch.argsort(sims, descending=True).tolist():
            a = self.caption_actions[i]
            if a and a not in best:
                best[a] = float(sims[i])
                if len(best) >= k:
                    break
        return list(best)


def read_known(folder) -> Known | None:
    """The folder's known texts, or None when it has none (older models)."""
    from safetensors.torch import load_file

    folder = Path(folder)
    j, v = folder / JSON_NAME, folder / VECTORS_NAME
    if not j.is_file() or not v.is_file():
        return None
    doc = read_json(j, JSON_NAME, MAX_KNOWN_BYTES, "copy the model folder again")
    try:
        vectors = load_file(str(v))["vectors"]
        captions, acts = list(doc["captions"]), list(doc["caption_actions"])
        actions = [(a, n) for a, n in doc["actions"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ShapeMoveError(f"{folder}: damaged {JSON_NAME}/{VECTORS_NAME} ({exc}); copy the model folder again") from None
    if vectors.ndim != 2 or len(vectors) != len(captions) or len(acts) != len(captions):
        raise ShapeMoveError(f"{folder}: {JSON_NAME} and {VECTORS_NAME} do not match; copy the model folder again")
    return Known([str(c) for c in captions], [str(a) for a in acts], actions, vectors)
