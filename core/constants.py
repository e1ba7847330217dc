"""Numbers and names that the whole project shares, in one leaf module (imports nothing, so
the Blender side, the mocap readers and the models can all use it).

FPS: every motion runs at 20 frames per second after import (HumanML3D). NUM_BETAS: a body shape
is 10 values ~N(0,1) in the body model's shape space. FSQ_LEVELS / NUM_CODES: the default motion
codebook (a model trained with other levels records its own count). Body-model ids: the bundled OpenBody's start
with ``openbody`` (``openbody-v1``, ``openbody-v2``, ...); anything else names a SMPL-family file.
"""
from __future__ import annotations

import math

FPS = 20
NUM_BETAS = 10
OPENBODY_PREFIX = "openbody"
# the SA-VAE's default FSQ levels and their codebook: the T5's motion vocabulary has one token per code
FSQ_LEVELS = (8, 5, 5, 5)
NUM_CODES = math.prod(FSQ_LEVELS)


def is_openbody(name) -> bool:
    """True for the id of the bundled OpenBody (any version), False for anything else."""
    return str(name or "").startswith(OPENBODY_PREFIX)
