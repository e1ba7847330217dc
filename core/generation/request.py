"""One generation request: the prompt, the body, the length and how to sample (``Generator.generate_batch``
and the animation features take it). Its own module so that the helpers ``generate.py`` uses can
build one without importing the generator."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .sampling_params import DEFAULT_CANDIDATES, DEFAULT_RETRIEVAL_FIRST, DEFAULT_RETRIEVAL_PREFIX, DEFAULT_RETRIEVED


@dataclass
class Request:
    prompt: str
    shape_text: str | None = None
    betas: np.ndarray | None = None
    seconds: float | None = None
    seed: int = 0
    temperature: float = 1.0
    top_k: int | None = 50
    shape_from: str = "auto"  # "auto": measurements stated in the shape text win; "head": the [BETA] head only
    candidates: int = DEFAULT_CANDIDATES  # token samples drawn; the TMA keeps the one closest to the prompt
    guidance: float | None = None  # classifier-free guidance scale; None: the model's default (0 without a null prompt)
    retrieval_prefix: int = DEFAULT_RETRIEVAL_PREFIX  # codes of a retrieved clip half the candidates start from (0: none)
    retrieved: int = DEFAULT_RETRIEVED  # real clips nearest by caption added to the candidates (0: none)
    retrieval_first: float | None = DEFAULT_RETRIEVAL_FIRST  # caption similarity from which only retrieved clips compete
    by_parts: bool = True  # two things at once composed by body part, a named side mirrored (parts.py)
    action: str | None = None  # the action the prompt names (the planner's reading): its captured clips compete alone
    plan: object | None = None  # an edited plan (``plan.plan.Plan``, ``generate --plan``): acted on instead of the prompt's reading
    words: object | None = None  # the reading the candidates are chosen by (``plan.words.Words``; None: the prompt's)
    whole_course: bool = False  # a timeline's segment: a course walks whole periods fitted to its travel (course_walk.py)
    seated: bool = False  # a timeline's segment after one that ends seated: a lie-down goes on from a sit (floor_sit.py)

    def reading(self):
        """What the candidates are chosen by: ``words`` when given, else the prompt's reading
        (``plan.words.read_words``, cached)."""
        from ..plan.words import read_words

        return self.words if self.words is not None else read_words(self.prompt)
