"""A numpy-only view of a body model, for Blender's Python where torch is usually missing.

``BodyArrays`` holds the same arrays as ``BodyModel`` (float64, metres, Y up, SMPL 24 joints) and
computes the rest shape without torch: rest_joints(betas), rest_vertices(betas), plus OpenBody's
phenotype map (semantic sliders -> betas; ``openbody_asset.PhenotypeMap``). It has the attribute names
``core.scene.rig_data`` reads (name, num_betas, v_template, shapedirs, joint_template,
joint_shapedirs, skin_weights, faces, parents), so the scene builder takes it like a BodyModel.
It cannot pose a body (no ``forward``): motions are made in the worker.

    body = load_body_arrays("openbody")          # or a path to an SMPL/SMPL-H/SMPL-X file
    body.rest_joints(betas)                      # (B,24,3)
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..constants import NUM_BETAS
from ..errors import ShapeMoveError
from .openbody_asset import DEFAULT_PATH, MODEL_ID, PhenotypeMap, read_openbody
from .skeleton import JOINT_NAMES, PARENTS


def rest_joints_for(joint_template, joint_shapedirs, betas) -> np.ndarray:
    """J(betas) of a linear body model: joint_template (J,3), joint_shapedirs (J,3,K), betas (..., K)
    -> (..., J, 3) rest joints (float64). The one numpy definition (the torch one is
    ``BodyModel.rest_joints``); any axes convention, as long as template and dirs share it."""
    t = np.asarray(joint_template, dtype=np.float64)
    d = np.asarray(joint_shapedirs, dtype=np.float64)
    return t + np.einsum("jck,...k->...jc", d, np.asarray(betas, dtype=np.float64))


@dataclass
class BodyArrays:
    name: str
    v_template: np.ndarray    # (V,3)
    shapedirs: np.ndarray     # (V,3,10)
    j_regressor: np.ndarray   # (24,V)
    skin_weights: np.ndarray  # (V,24)
    faces: np.ndarray         # (F,3) int64
    phenotype_map: PhenotypeMap | None = None                  # OpenBody only

    joint_names = JOINT_NAMES
    num_betas = NUM_BETAS

    def __post_init__(self):
        f64 = lambda a: np.asarray(a, dtype=np.float64)  # noqa: E731
        self.v_template, self.j_regressor, self.skin_weights = f64(self.v_template), f64(self.j_regressor), f64(self.skin_weights)
        sd = f64(self.shapedirs)[..., :NUM_BETAS]
        if sd.shape[-1] < NUM_BETAS:  # a smaller shape space is padded with zeros (as BodyModel does)
            sd = np.concatenate([sd, np.zeros(sd.shape[:-1] + (NUM_BETAS - sd.shape[-1],))], -1)
        self.shapedirs = sd
        self.faces = np.asarray(self.faces, dtype=np.int64)
        self.parents = PARENTS.copy()
        # joints are linear in betas: J(b) = J0 + Jdirs . b (same as BodyModel)
        self.joint_template = self.j_regressor @ self.v_template
        self.joint_shapedirs = np.einsum("jv,vcb->jcb", self.j_regressor, self.shapedirs)

    @property
    def num_vertices(self) -> int:
        return int(self.v_template.shape[0])

    @property
    def has_phenotypes(self) -> bool:
        return self.phenotype_map is not None

    @property
    def phenotype_names(self) -> list:
        return self.phenotype_map.names if self.phenotype_map is not None else []

    @property
    def phenotype_matrix(self) -> np.ndarray | None:
        """(P,10): the change of betas per unit of each slider."""
        return self.phenotype_map.matrix if self.phenotype_map is not None else None

    # -- shape ---------------------------------------------------------------------------------
    def _betas(self, betas) -> np.ndarray:
        b = np.zeros((1, NUM_BETAS)) if betas is None else np.asarray(betas, dtype=np.float64)
        if b.ndim == 1:
            b = b[None]
        if b.ndim != 2 or b.shape[-1] != NUM_BETAS:
            raise ShapeMoveError(f"betas must have {NUM_BETAS} values, got shape {b.shape}")
        if not np.isfinite(b).all():
            raise ShapeMoveError("betas contain NaN or infinite values")
        return b

    def rest_joints(self, betas=None) -> np.ndarray:
        """betas (10,) or (B,10) -> (B,24,3) rest-pose joints."""
        return rest_joints_for(self.joint_template, self.joint_shapedirs, self._betas(betas))

    def rest_vertices(self, betas=None) -> np.ndarray:
        """betas (10,) or (B,10) -> (B,V,3) rest-pose vertices."""
        return self.v_template + np.einsum("vcb,nb->nvc", self.shapedirs, self._betas(betas))

    # -- semantic sliders (OpenBody) ---------------------------------------------------------
    def _need_phenotypes(self):
        if not self.has_phenotypes:
            raise ShapeMoveError(f"body model {self.name!r} has no semantic sliders (only OpenBody has them)")

    def betas_from_phenotype(self, phenotype) -> np.ndarray:
        """(..., P) phenotype values (order ``phenotype_names``) or a dict -> (..., 10) betas."""
        self._need_phenotypes()
        return self.phenotype_map.to_betas(phenotype)

    def phenotype_from_betas(self, betas) -> np.ndarray:
        """(10,) betas -> (P,) the closest sliders, clipped to their ranges."""
        self._need_phenotypes()
        return self.phenotype_map.from_betas(self._betas(betas)[0])


def load_openbody_arrays(path=None) -> BodyArrays:
    """The bundled OpenBody asset (assets/openbody.npz) as BodyArrays, phenotype map included:
    the same validated arrays as the torch ``OpenBody`` (``openbody_asset.read_openbody``)."""
    d = read_openbody(path)
    return BodyArrays(name=str(d["model_id"]), v_template=d["v_template"], shapedirs=d["shapedirs"],
                      j_regressor=d["j_regressor"], skin_weights=d["skin_weights"], faces=d["faces"],
                      phenotype_map=PhenotypeMap(d))


def load_smpl_arrays(path) -> BodyArrays:
    """An SMPL / SMPL-H / SMPL-X model file (or its folder) as 24-joint BodyArrays (no pose
    correctives: the Blender rig skins linearly)."""
    try:
        from .smpl_family import (FAMILY_BY_JOINTS, _check_shapes, find_model_file, model_name,
                                  read_model_file, to_24_joints)
    except ImportError as exc:
        raise ShapeMoveError(f"reading SMPL-family files needs {exc.name or 'torch'} in this Python: set the "
                             "ShapeMove 'Python environment' preference, or use OpenBody") from None
    path = Path(path).expanduser()
    if path.is_dir():
        path = find_model_file(path)
    arrays = read_model_file(path)
    _check_shapes(arrays, str(path))
    m = to_24_joints(arrays)
    family = FAMILY_BY_JOINTS[np.asarray(arrays["J_regressor"]).shape[0]]
    return BodyArrays(name=model_name(path, family, arrays.get("gender")), v_template=arrays["v_template"],
                      shapedirs=arrays["shapedirs"], j_regressor=m["j_regressor"], skin_weights=m["skin_weights"],
                      faces=arrays["f"])


_CACHE: dict = {}


def load_body_arrays(spec=None) -> BodyArrays:
    """None / "openbody" / the OpenBody id -> OpenBody; otherwise a path to an SMPL-family file or
    folder. Cached per spec and file modification time (don't modify the result in place)."""
    if spec is None or str(spec).strip().lower() in ("", "openbody", MODEL_ID):
        key = ("openbody", DEFAULT_PATH.stat().st_mtime_ns if DEFAULT_PATH.is_file() else 0)
        loader = load_openbody_arrays
        arg = None
    else:
        p = Path(str(spec)).expanduser()
        if not p.exists():
            raise ShapeMoveError(f"body model {spec!r} is neither 'openbody' nor an existing SMPL-family file or folder")
        key = ("file", str(p.resolve()), p.stat().st_mtime_ns)
        loader, arg = load_smpl_arrays, p
    if key not in _CACHE:
        _CACHE[key] = loader(arg) if arg is not None else loader()
    return _CACHE[key]
