"""SMPL, SMPL-H and SMPL-X bodies from the user's own model files, as a 24-joint ``BodyModel``.

ShapeMove never ships these models (their licence forbids it): the user downloads them and passes
the path (``--body-model /path/to/SMPL_NEUTRAL.npz``). Accepted files are the official ``.npz``
and ``.pkl`` files (SMPL ``basicModel_*.pkl``, ``SMPL_*.pkl/.npz``, SMPL-H ``SMPLH_*.pkl`` or AMASS
``model.npz``, SMPL-X ``SMPLX_*.npz/.pkl``). Keys read: v_template (V,3), shapedirs (V,3,K),
J_regressor (J,V) dense or scipy.sparse, weights (V,J), kintree_table (2,J), f (F,3), optionally
posedirs (V,3,9(J-1)).

Reading is done here rather than by ``smplx.SMPL(...)`` because the official SMPL ``.pkl`` files are
Python-2 pickles holding ``chumpy`` arrays and chumpy is not installed (and does not import on
current numpy): the pickle is opened with ``encoding='latin1'`` and each chumpy array is rebuilt
from its pickled value (``x``), the same arrays ``smplx``'s ``tools/clean_ch.py`` would write.
The maths (shape blend shapes, pose correctives, FK, LBS) is the same as ``smplx.lbs.lbs``; the
tests compare against smplx on the same files.

Mapping to the SMPL 24 joints:
- SMPL: unchanged.
- SMPL-H (52 joints) / SMPL-X (55): joints 0..21 are the SMPL body joints. ``left_hand`` /
  ``right_hand`` (22/23) are regressed as the mean of the four finger knuckles (index, middle,
  ring, pinky base) of that hand, close to where SMPL puts its hand joint. Skinning weights of every
  finger joint are summed into the hand joint of its side, those of jaw and eyes into ``head``;
  so the fingers stay flat (SMPL-H/X zero hand pose with ``flat_hand_mean=True``).
- Pose-corrective blend shapes (posedirs) ARE applied, as smplx does, for the joints the 24-joint
  rig drives: all 23 for SMPL, the 21 body joints for SMPL-H/X (finger/jaw/eye rotations are zero).
  Pass ``pose_correctives=False`` for plain linear blend skinning.
"""
from __future__ import annotations

import pickle
import re
import zipfile
from pathlib import Path

import numpy as np
import torch

from ..errors import ShapeMoveError
from ..io.limits import check_file_size
from .model import BodyModel
from .skeleton import NUM_BODY_JOINTS, NUM_JOINTS, PARENTS

REQUIRED_KEYS = ("v_template", "shapedirs", "J_regressor", "weights", "kintree_table", "f")
EXTENSIONS = (".npz", ".pkl")
FAMILY_BY_JOINTS = {24: "smpl", 52: "smplh", 55: "smplx"}
# the four finger knuckles (index1, middle1, pinky1, ring1) of the left / right hand
KNUCKLES = {"smplh": ([22, 25, 28, 31], [37, 40, 43, 46]), "smplx": ([25, 28, 31, 34], [40, 43, 46, 49])}
HOW_TO = ("download the model yourself (SMPL: smpl.is.tue.mpg.de, SMPL-H: mano.is.tue.mpg.de, "
          "SMPL-X: smpl-x.is.tue.mpg.de), then pass --body-model /path/to/SMPL_NEUTRAL.npz "
          "(or .pkl); expected keys " + ", ".join(REQUIRED_KEYS))


# -- reading the files ---------------------------------------------------------------------------
# Model files are untrusted: the .pkl is read by an unpickler that resolves only the names below
# (never builtins, never a callable that could run code, write files or allocate without bound),
# and an .npz is read member by member with allow_pickle=False after checking each array header.
MAX_PICKLE_BYTES = 400 * 2**20  # official SMPL/SMPL-H/SMPL-X .pkl files are 40..250 MB
MAX_ARRAY_BYTES = 512 * 2**20  # all arrays we read, as float64; SMPL-X 2020 (400 betas) needs ~250 MB
_SPARSE_NAMES = ("csc_matrix", "csr_matrix", "coo_matrix", "csc_array", "csr_array", "coo_array")


class _ChumpyArray:
    """Stand-in for a pickled ``chumpy.Ch``: keeps its state; a plain Ch holds its value in ``x``."""

    def __new__(cls, *args, **kwargs):
        return object.__new__(cls)

    def __setstate__(self, state):
        self.state = state

    def value(self):
        x, depth = self, 0
        while isinstance(x, _ChumpyArray):  # iterative: a self-referencing pickle cannot recurse
            state = getattr(x, "state", None)
            x = state.get("x") if isinstance(state, dict) else None
            depth += 1
            if x is None or depth > 8:
                raise ValueError("a chumpy expression (not a plain array) cannot be read without chumpy")
        return np.asarray(x) if isinstance(x, np.ndarray) else _not_array(x)


def _not_array(x):
    raise ValueError(f"a chumpy value holds a {type(x).__name__}, not an array")


class _NdarrayClass:
    """What the pickle gets for ``numpy.ndarray``: only usable as the first argument of
    ``_reconstruct`` (calling it, which would allocate any size, fails)."""


_NDARRAY = _NdarrayClass()
_RECONSTRUCT = np.ndarray((0,)).__reduce__()[0]  # numpy.core.multiarray._reconstruct
_SCALAR = np.float64(0).__reduce__()[0]  # numpy.core.multiarray.scalar


def _reconstruct(cls, shape, dtype):
    """numpy's pickled-array constructor, for an empty ndarray only (its data comes with BUILD)."""
    if cls is not _NDARRAY or tuple(shape) != (0,):
        raise pickle.UnpicklingError("unexpected array constructor in a body-model file")
    return _RECONSTRUCT(np.ndarray, (0,), dtype)


def _scalar(dtype, data=None):
    if not isinstance(dtype, np.dtype) or dtype.hasobject or not isinstance(data, bytes) or len(data) > 64:
        raise pickle.UnpicklingError("unexpected numpy scalar in a body-model file")
    return _SCALAR(dtype, data)


def _make_set(items=()):
    return set(items)


def _copyreg_reconstructor(cls, base, state):
    """Python 2 pickles create new-style objects this way; allow only the chumpy stand-in."""
    if cls is not _ChumpyArray:
        raise pickle.UnpicklingError("unexpected object constructor in a body-model file")
    return object.__new__(_ChumpyArray)


def _encode(text, encoding="latin1"):
    if not isinstance(text, str) or encoding not in ("latin1", "latin-1", "utf-8", "utf8"):
        raise pickle.UnpicklingError("unexpected text encoding in a body-model file")
    return text.encode(encoding)


_ALLOWED = {
    ("numpy", "dtype"): np.dtype, ("numpy", "ndarray"): _NDARRAY,
    ("numpy.core.multiarray", "_reconstruct"): _reconstruct, ("numpy._core.multiarray", "_reconstruct"): _reconstruct,
    ("numpy.core.multiarray", "scalar"): _scalar, ("numpy._core.multiarray", "scalar"): _scalar,
    ("copy_reg", "_reconstructor"): _copyreg_reconstructor, ("copyreg", "_reconstructor"): _copyreg_reconstructor,
    ("__builtin__", "set"): _make_set, ("builtins", "set"): _make_set,
    ("__builtin__", "object"): None, ("builtins", "object"): None,  # only as copy_reg's base argument
    ("_codecs", "encode"): _encode,
}


class _ModelUnpickler(pickle.Unpickler):
    """Resolves only what an SMPL-family pickle holds: numpy arrays / dtypes, scipy.sparse
    matrices, chumpy arrays (as ``_ChumpyArray``). Anything else is refused."""

    def find_class(self, module, name):
        if module.split(".")[0] == "chumpy" and name == "Ch":
            return _ChumpyArray
        if module.startswith("scipy.sparse") and name in _SPARSE_NAMES:
            import scipy.sparse

            return getattr(scipy.sparse, name)
        if (module, name) in _ALLOWED:
            return _ALLOWED[(module, name)]
        raise pickle.UnpicklingError(f"refused to load {module}.{name} from a body-model file (only numpy arrays, "
                                     "scipy.sparse matrices and chumpy arrays are allowed)")


def _plain(value, key: str):
    """chumpy / scipy.sparse / ndarray -> a numeric ndarray, size-checked before any allocation."""
    if isinstance(value, _ChumpyArray):
        value = value.value()
    module = type(value).__module__ or ""
    if module.startswith("scipy.sparse") and hasattr(value, "toarray"):
        shape = tuple(int(n) for n in value.shape)
        if len(shape) != 2 or shape[0] * shape[1] * 8 > MAX_ARRAY_BYTES:
            raise ValueError(f"{key} is a sparse matrix of shape {shape}, too large for a body model")
        value.check_format(full_check=True)  # indices inside the shape, before any C code uses them
        return value.toarray()
    if not isinstance(value, np.ndarray):
        if key == "gender" and isinstance(value, (str, bytes)):
            return np.asarray(value)
        raise ValueError(f"{key} holds a {type(value).__name__}, not an array")
    if key != "gender" and value.dtype.kind not in "biuf":
        raise ValueError(f"{key} holds {value.dtype} values, not numbers")
    return value


def _check_sizes(arrays: dict) -> None:
    total = sum(int(np.prod(a.shape, dtype=np.float64)) * 8 for a in arrays.values())
    if total > MAX_ARRAY_BYTES:
        raise ValueError(f"its arrays would take {total / 2**20:.0f} MB, more than any SMPL-family model "
                         f"({MAX_ARRAY_BYTES // 2**20} MB)")


def read_model_file(path: str | Path) -> dict:
    """Read an SMPL-family ``.npz`` / ``.pkl`` into a dict of numpy arrays (only the keys we use)."""
    path = Path(path).expanduser()
    if not path.is_file():
        raise ShapeMoveError(f"body model file {path} not found: {HOW_TO}")
    if path.suffix.lower() not in EXTENSIONS:
        raise ShapeMoveError(f"body model file {path} has extension '{path.suffix}', expected .npz or .pkl: {HOW_TO}")
    wanted = REQUIRED_KEYS + ("posedirs", "gender")
    try:
        if path.suffix.lower() == ".npz":
            from ..io.npz_read import read_npz

            raw = read_npz(path, wanted, MAX_ARRAY_BYTES, skip_objects=("gender",), what="SMPL-family model")
        else:
            check_file_size(path, MAX_PICKLE_BYTES, "SMPL-family .pkl")
            with open(path, "rb") as fh:
                raw = _ModelUnpickler(fh, encoding="latin1").load()
            if not isinstance(raw, dict):
                raise ValueError(f"the pickle holds a {type(raw).__name__}, not a dict of arrays")
            raw = {k: raw[k] for k in wanted if k in raw}
        out = {k: _plain(v, k) for k, v in raw.items()}
        _check_sizes({k: v for k, v in out.items() if k != "gender"})
    except ShapeMoveError as exc:  # from read_npz: "PATH: what is wrong"
        raise ShapeMoveError(f"could not read body model file {exc}. {HOW_TO}") from None
    except MemoryError:
        raise ShapeMoveError(f"could not read body model file {path}: it does not fit in memory. {HOW_TO}") from None
    except (OSError, ValueError, TypeError, EOFError, KeyError, AttributeError, IndexError, ImportError,
            RecursionError, pickle.UnpicklingError, zipfile.BadZipFile, zipfile.LargeZipFile) as exc:
        raise ShapeMoveError(f"could not read body model file {path}: {exc}. {HOW_TO}") from None
    missing = [k for k in REQUIRED_KEYS if k not in out]
    if missing:
        raise ShapeMoveError(f"body model file {path} lacks key(s) {', '.join(missing)}: is it an SMPL/SMPL-H/SMPL-X "
                             f"model? {HOW_TO}")
    return out


# -- checking and converting ---------------------------------------------------------------------
def _check_shapes(a: dict, where: str) -> tuple[int, int]:
    """Validate the arrays; return (num_vertices, num_joints)."""
    def bad(msg):
        return ShapeMoveError(f"body model {where}: {msg}. {HOW_TO}")

    for k in REQUIRED_KEYS + ("posedirs",):
        if k in a and (np.asarray(a[k]).dtype.kind not in "biuf" or not np.all(np.isfinite(a[k]))):
            raise bad(f"{k} holds NaN, infinite or non-numeric values")
    v = np.asarray(a["v_template"])
    if v.ndim != 2 or v.shape[1] != 3:
        raise bad(f"v_template should be (V,3), got {v.shape}")
    V = v.shape[0]
    sd = np.asarray(a["shapedirs"])
    if sd.ndim != 3 or sd.shape[:2] != (V, 3) or sd.shape[2] < 1:
        raise bad(f"shapedirs should be ({V},3,K), got {sd.shape}")
    jr = np.asarray(a["J_regressor"])
    if jr.ndim != 2 or jr.shape[1] != V:
        raise bad(f"J_regressor should be (J,{V}), got {jr.shape}")
    J = jr.shape[0]
    if J not in FAMILY_BY_JOINTS:
        raise bad(f"{J} joints; expected 24 (SMPL), 52 (SMPL-H) or 55 (SMPL-X) - MANO/FLAME are not body models")
    if np.asarray(a["weights"]).shape != (V, J):
        raise bad(f"weights should be ({V},{J}), got {np.asarray(a['weights']).shape}")
    if np.asarray(a["kintree_table"]).shape != (2, J):
        raise bad(f"kintree_table should be (2,{J}), got {np.asarray(a['kintree_table']).shape}")
    f = np.asarray(a["f"])
    if f.ndim != 2 or f.shape[1] != 3 or (f.size and (f.min() < 0 or f.max() >= V)):
        raise bad(f"f should be (F,3) vertex indices below {V}, got shape {f.shape}")
    if "posedirs" in a and np.asarray(a["posedirs"]).shape != (V, 3, 9 * (J - 1)):
        raise bad(f"posedirs should be ({V},3,{9 * (J - 1)}), got {np.asarray(a['posedirs']).shape}")
    parents = _parents(a)
    if np.any(parents[1:] < 0) or np.any(parents[1:] >= np.arange(1, J)):
        raise bad("kintree_table is not a joint tree (every parent must come before its child)")
    n = NUM_JOINTS if J == NUM_JOINTS else NUM_BODY_JOINTS
    if not np.array_equal(parents[:n], PARENTS[:n]):
        raise bad("kintree_table is not the SMPL joint tree")
    return V, J


def _parents(a: dict) -> np.ndarray:
    parents = np.asarray(a["kintree_table"])[0].astype(np.int64)
    parents[0] = -1  # stored as 2**32-1
    return parents


def to_24_joints(a: dict) -> dict:
    """SMPL/SMPL-H/SMPL-X arrays -> 24-joint arrays (see module docstring for the mapping).

    Returns j_regressor (24,V), skin_weights (V,24), family, and the number of joints (after the
    root) whose pose correctives the 24-joint rig drives.
    """
    jr = np.asarray(a["J_regressor"], dtype=np.float64)
    w = np.asarray(a["weights"], dtype=np.float64)
    J = jr.shape[0]
    family = FAMILY_BY_JOINTS[J]
    if family == "smpl":
        return {"j_regressor": jr, "skin_weights": w, "family": family, "posed_joints": NUM_JOINTS - 1}
    parents = _parents(a)
    group = np.arange(J)
    for j in range(NUM_BODY_JOINTS, J):
        anc = j
        while anc >= NUM_BODY_JOINTS:
            anc = parents[anc]
        group[j] = {20: 22, 21: 23}.get(int(anc), int(anc))
    weights = np.zeros((w.shape[0], NUM_JOINTS))
    np.add.at(weights.T, group, w.T)
    left, right = KNUCKLES[family]
    if any(parents[k] != 20 for k in left) or any(parents[k] != 21 for k in right):
        raise ShapeMoveError(f"{family} model: finger joints are not where expected (children of the wrists)")
    reg = np.concatenate([jr[:NUM_BODY_JOINTS], jr[left].mean(0, keepdims=True), jr[right].mean(0, keepdims=True)])
    return {"j_regressor": reg, "skin_weights": weights, "family": family, "posed_joints": NUM_BODY_JOINTS - 1}


def model_name(path: Path, family: str, gender_key=None) -> str:
    """'smplx-male' etc. from the file name, its folder (AMASS: male/model.npz) or a gender key."""
    aliases = {"f": "female", "female": "female", "m": "male", "male": "male", "neutral": "neutral"}
    for text in (path.stem, path.parent.name):
        for tok in re.split(r"[^a-z]+", text.lower()):
            if tok in aliases:
                return f"{family}-{aliases[tok]}"
    if gender_key is not None:
        g = np.asarray(gender_key).item()
        g = (g.decode() if isinstance(g, bytes) else str(g)).lower()
        if g in aliases:
            return f"{family}-{aliases[g]}"
    return f"{family}-{path.stem.lower()}"


def find_model_file(folder: Path, gender: str = "neutral") -> Path:
    """The one model file in ``folder`` (or its smpl/smplh/smplx subfolders), preferring ``gender``."""
    files = sorted(p for d in (folder, folder / "smpl", folder / "smplh", folder / "smplx") if d.is_dir()
                   for p in d.iterdir() if p.suffix.lower() in EXTENSIONS and p.is_file())
    if len(files) > 1:
        tagged = [p for p in files if model_name(p, "x").endswith("-" + gender)]
        files = tagged or files
    if not files:
        raise ShapeMoveError(f"no .npz/.pkl body model in {folder}: {HOW_TO}")
    if len(files) > 1:
        names = ", ".join(str(p) for p in files)
        raise ShapeMoveError(f"several body models in {folder} ({names}): pass the file you want to --body-model")
    return files[0]


# -- the body model ------------------------------------------------------------------------------
class SMPLFamilyBody(BodyModel):
    """A 24-joint ``BodyModel`` from an SMPL / SMPL-H / SMPL-X file; pose correctives optional.

    Extra buffer ``posedirs`` (P,V*3) with P = 9 * ``posed_joints`` (smplx layout), or None.
    """

    def __init__(self, arrays: dict, name: str, pose_correctives: bool = True, where: str = "arrays"):
        V, J = _check_shapes(arrays, where)
        m = to_24_joints(arrays)
        super().__init__(arrays["v_template"], arrays["shapedirs"], m["j_regressor"], m["skin_weights"],
                         arrays["f"], name=name)
        self.family = m["family"]
        self.posed_joints = m["posed_joints"]
        posedirs = None
        if pose_correctives and "posedirs" in arrays:
            pd = np.asarray(arrays["posedirs"], dtype=np.float32)
            posedirs = torch.from_numpy(pd.reshape(-1, pd.shape[-1]).T[: 9 * self.posed_joints].copy())
        self.register_buffer("posedirs", posedirs)

    @classmethod
    def load(cls, path: str | Path, gender: str = "neutral", pose_correctives: bool = True) -> "SMPLFamilyBody":
        """From a model file, or a folder holding one (``gender`` picks among several)."""
        path = Path(path).expanduser()
        if path.is_dir():
            path = find_model_file(path, gender)
        arrays = read_model_file(path)
        family = FAMILY_BY_JOINTS.get(np.asarray(arrays["J_regressor"]).shape[0], "smpl")
        return cls(arrays, model_name(path, family, arrays.get("gender")), pose_correctives, where=str(path))

    def pose_offsets(self, rotmats: torch.Tensor) -> torch.Tensor | None:
        """The pose-corrective offsets (smplx's ``lbs``): posedirs . (R - I) of the body joints."""
        if self.posedirs is None:
            return None
        B = rotmats.shape[0]
        eye = torch.eye(3, dtype=rotmats.dtype, device=rotmats.device)
        feature = (rotmats[:, 1: 1 + self.posed_joints] - eye).reshape(B, -1)
        return (feature @ self.posedirs).reshape(B, -1, 3)
