"""Moved to ``core/body/sole_height.py`` (the body's soles are body maths; the body never imports
``core/scene/``). Re-exported here for older callers."""
from ..body.sole_height import (  # noqa: F401  (re-exported)
    DIRECTIONS, RIGID, SOLE_BAND, lowest_heights, sole_vertices)
