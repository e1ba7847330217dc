"""The OpenBody asset file (assets/openbody.npz): its id, its format version and the one reader
that checks them. Numpy only, so the torch ``OpenBody`` model and Blender's numpy ``BodyArrays``
read the same validated arrays (``read_openbody``).
"""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from ..constants import NUM_BETAS
from ..errors import ShapeMoveError
from .skeleton import JOINT_NAMES, NUM_JOINTS

FORMAT_VERSION = 1
MODEL_ID = "openbody-v1"
DEFAULT_PATH = Path(__file__).resolve().parents[2] / "assets" / "openbody.npz"
REBUILD_HINT = "rebuild it with: python tools/build_openbody.py --out assets/openbody.npz --seed 0"

REQUIRED = ["format_version", "model_id", "v_template", "shapedirs", "j_regressor", "skin_weights",
            "faces", "joint_names", "phenotype_names", "phenotype_ranges", "phenotype_defaults",
            "phenotype_intercept", "phenotype_matrix"]


def read_openbody(path: str | Path | None = None) -> dict:
    """The asset's arrays (default: assets/openbody.npz of this package), checked: every required
    array present, this format version and model id, shapes consistent, joints in SMPL order.
    Anything else -> ShapeMoveError saying how to rebuild the asset."""
    path = Path(path) if path is not None else DEFAULT_PATH
    if not path.is_file():
        raise ShapeMoveError(f"OpenBody asset not found at {path}; {REBUILD_HINT}")
    try:
        with np.load(path, allow_pickle=False) as npz:
            data = {k: npz[k] for k in npz.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise ShapeMoveError(f"OpenBody asset {path} is unreadable ({exc}); {REBUILD_HINT}") from None
    missing = [k for k in REQUIRED if k not in data]
    if missing:
        raise ShapeMoveError(f"OpenBody asset {path} lacks {', '.join(missing)}; {REBUILD_HINT}")
    if int(data["format_version"]) != FORMAT_VERSION or str(data["model_id"]) != MODEL_ID:
        raise ShapeMoveError(
            f"OpenBody asset {path} is {data['model_id']} format {int(data['format_version'])}, "
            f"expected {MODEL_ID} format {FORMAT_VERSION}; {REBUILD_HINT}")
    V = data["v_template"].shape[0]
    shapes = {"v_template": (V, 3), "shapedirs": (V, 3, NUM_BETAS), "j_regressor": (NUM_JOINTS, V),
              "skin_weights": (V, NUM_JOINTS), "phenotype_matrix": (len(data["phenotype_names"]), NUM_BETAS),
              "phenotype_intercept": (NUM_BETAS,), "phenotype_ranges": (len(data["phenotype_names"]), 2)}
    for key, shape in shapes.items():
        if data[key].shape != shape:
            raise ShapeMoveError(f"OpenBody asset {path}: {key} has shape {data[key].shape}, "
                                 f"expected {shape}; {REBUILD_HINT}")
    if data["faces"].ndim != 2 or data["faces"].shape[1] != 3 or data["faces"].min() < 0 or data["faces"].max() >= V:
        raise ShapeMoveError(f"OpenBody asset {path}: faces must be (F,3) vertex indices below {V}; {REBUILD_HINT}")
    if list(data["joint_names"]) != JOINT_NAMES:
        raise ShapeMoveError(f"OpenBody asset {path} has joints out of SMPL order; {REBUILD_HINT}")
    return data


class PhenotypeMap:
    """OpenBody's semantic sliders (gender, age, muscle, weight, height, proportions) and their
    linear map to betas, as stored in the asset: ``betas = intercept + phenotype @ matrix``.

    names (P,) str; ranges (P,2) slider min, max; defaults (P,) values whose betas are ~0;
    intercept (10,); matrix (P,10). Shared by the torch ``OpenBody`` and the numpy ``BodyArrays``.
    """

    def __init__(self, data: dict):
        self.names = [str(n) for n in data["phenotype_names"]]
        self.ranges = np.asarray(data["phenotype_ranges"], dtype=np.float64)
        self.defaults = np.asarray(data["phenotype_defaults"], dtype=np.float64)
        self.intercept = np.asarray(data["phenotype_intercept"], dtype=np.float64)
        self.matrix = np.asarray(data["phenotype_matrix"], dtype=np.float64)
        self.r2 = np.asarray(data["phenotype_r2"], dtype=np.float64) if "phenotype_r2" in data else None  # per beta

    def array(self, phenotype) -> np.ndarray:
        """dict (missing names take their defaults) or array (..., P) -> float array (..., P)."""
        if isinstance(phenotype, dict):
            unknown = set(phenotype) - set(self.names)
            if unknown:
                raise ShapeMoveError(f"unknown phenotype {sorted(unknown)}; known: {self.names}")
            values = []
            for i, n in enumerate(self.names):
                try:
                    values.append(float(phenotype.get(n, self.defaults[i])))
                except (TypeError, ValueError):
                    raise ShapeMoveError(f"phenotype {n} must be a number, got {phenotype[n]!r}") from None
            p = np.array(values)
        else:
            p = np.asarray(phenotype, dtype=np.float64)
            if p.shape[-1:] != (len(self.names),):
                raise ShapeMoveError(f"phenotype must be {len(self.names)} values "
                                     f"({', '.join(self.names)}), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ShapeMoveError("phenotype values must be finite numbers")
        return p

    def to_betas(self, phenotype) -> np.ndarray:
        """Sliders (dict or (..., P)) -> betas (..., 10) float64; values outside ``ranges`` extrapolate."""
        return self.intercept + self.array(phenotype) @ self.matrix

    def from_betas(self, betas) -> np.ndarray:
        """(10,) betas -> (P,) the sliders whose betas are closest (least squares), clipped to the
        ranges: where the sliders start for a body made elsewhere."""
        b = np.asarray(betas, dtype=np.float64).reshape(-1)
        if b.shape != (NUM_BETAS,) or not np.isfinite(b).all():
            raise ShapeMoveError(f"betas must be {NUM_BETAS} finite values, got shape {b.shape}")
        p, *_ = np.linalg.lstsq(self.matrix.T, b - self.intercept, rcond=None)
        return np.clip(p, self.ranges[:, 0], self.ranges[:, 1])
