"""Best of N: several motion-token samples for one prompt, the one the text-motion model (TMA,
Human TOMATO's alignment model) finds closest to the prompt is kept. Where the words name an action,
the TMA reads them and that action as the captions say it ("a person raises a hand"), half each
(``action_phrase``): the TMA was trained on captions, and a user's wording can pull it off the action
asked ("she throws both hands up" scored the takes raising both hands 0.05-0.07, samples with the
hands at the chest 0.5-0.7). On the tuning paraphrases the raw-feature judge, which never reads the
TMA, rose 39.4 -> 45.4 % with it (docs/design-notes.md).

The T5 samples its tokens; for prompts far from the common training actions a single sample often
drifts to a frequent motion (a walk, a raised hand). ``pick`` decodes every candidate's features
with the SA-VAE and compares their TMA motion embeddings with the prompt's TMA text embedding
(cosine); the highest wins. The TMA is the model's own (``tma/`` of the model folder), so choosing
costs one batched SA-VAE decode and one TMA pass (tens of milliseconds), not a second generator.

Travel and pace words come first: a candidate whose root travel goes against "forward",
"backwards", "in place" or "steps to the left" is set aside before the TMA chooses
(``travel_words``), for "walks quickly" or "a brisk walk" only the fastest candidates compete
(``pace_words``), and for "jumps twice" or "three squats" only those that leave the floor or go
down the number of times nearest the asked one (``count_words``), for "walks 3 metres" those
whose path gets that far (``stop_words``), for "gets up" or "lies down" those that rise or go
down (``posture_change``), for "picks up" or "puts down" those whose hand reaches the floor
(``floor_reach``), and for "both arms" those made with both (``hands_asked``), since the TMA reads what the body does, not which way, how fast, how far
or how many times, and weighs who does it as much as what.

Bias to keep in mind: R-precision and the paraphrase classifier also read TMA embeddings, so
``eval generate`` scores the generator with one candidate, and ``eval paraphrase`` also reports a
classifier that does not use the TMA (``action_classifier.FeatureEmbedder``).
"""
from __future__ import annotations

import numpy as np

from ..plan.words import read_words
from .count_words import counter, nearest_count
from .floor_reach import floor_reached
from .gait_steps import stepping, striking
from .hands_asked import both_kept
from .pace_words import fastest, gait_speed, going, staying
from .posture_change import posture_kept
from .stop_words import reaching
from .travel_words import allowed


class CandidatePicker:
    def __init__(self, tma):
        """``tma``: a ``tma_embed.load_tma`` tuple (model, text reader, mean, std)."""
        self.model, self.tok, self.mean, self.std = tma

    def scores(self, prompt: str, feats: list) -> np.ndarray:
        """(N,) cosine similarity of each candidate's (T, 263) features to the prompt."""
        return self.similarities([prompt], feats)[0]

    def similarities(self, texts: list[str], feats: list) -> list[np.ndarray]:
        """For each text, the (N,) cosine similarity of each candidate's (T, 263) features to it (the
        candidates embedded once)."""
        from ..models.tma_embed import embed_motions, embed_texts

        vectors = [embed_texts(self.model, self.tok, [t])[0] for t in texts]   # each alone: no padding
        motions = embed_motions(self.model, feats, self.mean, self.std)
        return [motions @ v for v in vectors]

    def pick(self, prompt: str, feats: list, bonus=None, words=None, reach: float | None = None) -> int:
        """Index of the candidate closest to ``prompt`` among those that obey the travel, pace (a
        gait that goes somewhere: ``pace_words.going``) and count of its plan (``words``: a
        ``plan.words.Words``, else the prompt's reading; the first on a tie); ``bonus`` (N,): added
        to the similarities (a captured take of the asked action, ``captured_takes.ACTION_BONUS``);
        ``reach``: a distance (m) asked of a gait cut where it gets there (``stop_words.reaching``:
        those whose path is that long, when one is)."""
        words = read_words(prompt) if words is None else words
        keep = allowed(words.travel, feats)
        if reach is not None:
            keep = reaching(feats, reach, keep)
        speeds = np.array([gait_speed(f) for f in feats])
        keep = going(words, speeds, keep)   # a gait asked to go somewhere: not one that stands about
        keep = stepping(words, feats, keep)   # ... nor one that slides along without stepping
        keep = staying(words, speeds, keep)   # an exercise or a gesture: not one that walks off
        if words.pace == "fast":
            keep = fastest(speeds, keep)
        if words.steps is not None:   # "takes three steps": candidates that step that many times
            keep = striking(feats, words.steps, keep)
        if words.count is not None:
            action, want = words.count
            keep = nearest_count([counter(action)(f) for f in feats], want, keep)
        keep = posture_kept(words.actions[0] if words.actions else None, feats, keep)
        keep = floor_reached(words.actions[0] if words.actions else None, feats, keep)
        keep = both_kept(words, feats, keep)   # "both arms": not a candidate made with one
        phrase = action_phrase(words)   # the action asked, in the captions' words, read beside the user's
        sims = self.similarities([prompt] + ([phrase] if phrase is not None else []), feats)
        scores = sims[0] if phrase is None else (sims[0] + sims[1]) / 2
        scores = scores + (0.0 if bonus is None else np.asarray(bonus, np.float64))
        return int(np.argmax(np.where(keep, scores, -np.inf)))


def action_phrase(words) -> str | None:
    """The action the words ask (its specific form: a limp, not the walk), as the captions say it ("a
    person raises a hand"); None when they name none or more than one ("turns around and walks away":
    the words alone, or the turn would pull the choice to the samples that stay). The TMA reads a
    user's wording as it was trained to: "she throws both hands up" scored the takes raising both
    hands 0.05-0.07 against 0.5-0.7 for samples with the hands at the chest."""
    from ..data.actions import ACTIONS, specific

    acts = specific(list(words.actions))
    return f"a person {ACTIONS[acts[0]].phrases[0]}" if len(acts) == 1 and acts[0] in ACTIONS else None
