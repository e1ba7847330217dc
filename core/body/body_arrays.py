"""A numpy-only view of a body model, for Blender's Python where torch is usually missing.

``BodyArrays`` holds the same arrays as ``BodyModel`` (float64, metres, Y up, SMPL 24 joints) and
computes the rest shape without torch: rest_joints(betas), rest_vertices(betas), shape-key
coordinates, plus OpenBody's phenotype map (semantic sliders -> betas). It has the attribute names
``core.scene.rig_data`` reads (name, num_betas, v_template, shapedirs, joint_template,
joint_shapedirs, skin_weights, faces, parents), so the scene builder takes it like a BodyModel.
It cannot pose a body (no ``forward``): motions are made in the worker.

    body = load_body_arrays("openbody")          # or a path to an SMPL/SMPL-H/SMPL-X file
    body.rest_joints(betas)                      # (B,24,3)
"""
from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ShapeMoveError
from .skeleton import JOINT_NAMES, PARENTS

NUM_BETAS = 10
OPENBODY_PATH = Path(__file__).resolve().parents[2] / "assets" / "openbody.npz"
OPENBODY_ID = "openbody-v1"


@dataclass
class BodyArrays:
    name: str
    v_template: np.ndarray    # (V,3)
    shapedirs: np.ndarray     # (V,3,10)
    j_regressor: np.ndarray   # (24,V)
    skin_weights: np.ndarray  # (V,24)
    faces: np.ndarray         # (F,3) int64
    phenotype_names: list = field(default_factory=list)       # OpenBody only (else empty)
    phenotype_ranges: np.ndarray | None = None                 # (P,2) slider min, max
    phenotype_defaults: np.ndarray | None = None               # (P,)
    phenotype_intercept: np.ndarray | None = None              # (10,)
    phenotype_matrix: np.ndarray | None = None                 # (P,10)

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
        return self.phenotype_matrix is not None

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
        return self.joint_template + np.einsum("jcb,nb->njc", self.joint_shapedirs, self._betas(betas))

    def rest_vertices(self, betas=None) -> np.ndarray:
        """betas (10,) or (B,10) -> (B,V,3) rest-pose vertices."""
        return self.v_template + np.einsum("vcb,nb->nvc", self.shapedirs, self._betas(betas))

    def shape_key_coords(self) -> np.ndarray:
        """(10,V,3): absolute coordinates of shape key i = template + shapedirs[..., i]."""
        return self.v_template[None] + np.moveaxis(self.shapedirs, -1, 0)

    # -- semantic sliders (OpenBody) ---------------------------------------------------------
    def _need_phenotypes(self):
        if not self.has_phenotypes:
            raise ShapeMoveError(f"body model {self.name!r} has no semantic sliders (only OpenBody has them)")

    def betas_from_phenotype(self, phenotype) -> np.ndarray:
        """(..., P) phenotype values (order ``phenotype_names``) -> (..., 10) betas (the asset's linear map)."""
        self._need_phenotypes()
        p = np.asarray(phenotype, dtype=np.float64)
        if p.shape[-1:] != (len(self.phenotype_names),) or not np.isfinite(p).all():
            raise ShapeMoveError(f"phenotype must be {len(self.phenotype_names)} finite values "
                                 f"({', '.join(self.phenotype_names)}), got shape {p.shape}")
        return self.phenotype_intercept + p @ self.phenotype_matrix

    def phenotype_from_betas(self, betas) -> np.ndarray:
        """(10,) betas -> (P,) the phenotype whose betas are closest (least squares), clipped to
        the slider ranges: where the semantic sliders start for a body made elsewhere."""
        self._need_phenotypes()
        b = self._betas(betas)[0]
        p, *_ = np.linalg.lstsq(self.phenotype_matrix.T, b - self.phenotype_intercept, rcond=None)
        return np.clip(p, self.phenotype_ranges[:, 0], self.phenotype_ranges[:, 1])


def _read_npz(path: Path, what: str) -> dict:
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise ShapeMoveError(f"{what} {path} is unreadable ({exc})") from None


def load_openbody_arrays(path=None) -> BodyArrays:
    """The bundled OpenBody asset (assets/openbody.npz) as BodyArrays, phenotype map included."""
    path = Path(path) if path is not None else OPENBODY_PATH
    if not path.is_file():
        raise ShapeMoveError(f"OpenBody asset not found at {path}; rebuild it with tools/build_openbody.py")
    d = _read_npz(path, "OpenBody asset")
    need = ["model_id", "v_template", "shapedirs", "j_regressor", "skin_weights", "faces", "joint_names"]
    missing = [k for k in need if k not in d]
    if missing:
        raise ShapeMoveError(f"OpenBody asset {path} lacks {', '.join(missing)}")
    if list(d["joint_names"]) != JOINT_NAMES:
        raise ShapeMoveError(f"OpenBody asset {path} has joints out of SMPL order")
    ph = "phenotype_matrix" in d
    return BodyArrays(
        name=str(d["model_id"]), v_template=d["v_template"], shapedirs=d["shapedirs"], j_regressor=d["j_regressor"],
        skin_weights=d["skin_weights"], faces=d["faces"],
        phenotype_names=[str(n) for n in d["phenotype_names"]] if ph else [],
        phenotype_ranges=np.asarray(d["phenotype_ranges"], np.float64) if ph else None,
        phenotype_defaults=np.asarray(d["phenotype_defaults"], np.float64) if ph else None,
        phenotype_intercept=np.asarray(d["phenotype_intercept"], np.float64) if ph else None,
        phenotype_matrix=np.asarray(d["phenotype_matrix"], np.float64) if ph else None,
    )


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
    """None / "openbody" / "openbody-v1" -> OpenBody; otherwise a path to an SMPL-family file or
    folder. Cached per spec and file modification time (don't modify the result in place)."""
    if spec is None or str(spec).strip().lower() in ("", "openbody", OPENBODY_ID):
        key = ("openbody", OPENBODY_PATH.stat().st_mtime_ns if OPENBODY_PATH.is_file() else 0)
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
