"""Semantic shape sliders (height, weight, age, muscle, gender, proportions) for OpenBody rigs.

OpenBody ships a linear map  betas = intercept + phenotype . M  (6 sliders -> 10 betas). A slider
move from p to p' adds (p' - p) . M to the rig's current betas, so hand-tuned betas survive a
slider change. The slider values live on the armature ("shapemove_phenotype"); a rig without
them starts from the phenotype closest to its betas (least squares, clipped to the ranges).
"""
from __future__ import annotations

import numpy as np

from ..core.body.body_arrays import load_body_arrays
from ..core.constants import is_openbody
from ..core.errors import ShapeMoveError
from . import shape_sync
from .rig_state import current_betas

PHENOTYPE_KEY = "shapemove_phenotype"
# name -> (label, soft min, soft max, description); the order of the panel
PHENOTYPES = {
    "height": ("Height", 0.2, 0.55, "Body height (OpenBody's height slider)"),
    "weight": ("Weight", 0.0, 1.0, "Body weight, thin .. heavy"),
    "age": ("Age", 18.0, 80.0, "Age in years"),
    "muscle": ("Muscle", 0.0, 1.0, "Muscularity"),
    "gender": ("Gender", 0.0, 1.0, "0 = male .. 1 = female"),
    "proportions": ("Proportions", 0.0, 1.0, "Body proportions, ideal .. uncommon"),
}


def semantic_body(rig):
    """The numpy body with the phenotype map for ``rig``'s body model, or None (not OpenBody)."""
    if rig is None or not is_openbody(rig.get("shapemove_body_model", "")):
        return None
    body = load_body_arrays("openbody")
    return body if body.has_phenotypes else None


def phenotype_values(rig) -> dict:
    """{name: value} of the rig's semantic sliders (empty when the body has none)."""
    body = semantic_body(rig)
    if body is None:
        return {}
    stored = rig.get(PHENOTYPE_KEY)
    if stored is not None and len(stored) == len(body.phenotype_names):
        values = np.asarray(stored, dtype=np.float64)
    else:
        values = body.phenotype_from_betas(current_betas(rig))
    return dict(zip(body.phenotype_names, values.tolist()))


def set_phenotype(rig, name: str, value: float, context=None) -> np.ndarray:
    """Move one semantic slider; returns the rig's new betas (10,)."""
    body = semantic_body(rig)
    if body is None:
        raise ShapeMoveError(f"{rig.name!r} is not an OpenBody rig: semantic sliders need OpenBody")
    if name not in body.phenotype_names:
        raise ShapeMoveError(f"unknown shape slider {name!r}; known: {', '.join(body.phenotype_names)}")
    current = phenotype_values(rig)
    old = np.array([current[n] for n in body.phenotype_names])
    new = old.copy()
    new[body.phenotype_names.index(name)] = float(value)
    betas = current_betas(rig) + (new - old) @ body.phenotype_matrix
    rig[PHENOTYPE_KEY] = new.tolist()
    shape_sync.set_betas(rig, betas, context)
    return betas


def forget_phenotype(rig) -> None:
    """After the betas were set wholesale (random, reset, from text): re-derive the sliders."""
    if rig is not None and PHENOTYPE_KEY in rig:
        del rig[PHENOTYPE_KEY]
