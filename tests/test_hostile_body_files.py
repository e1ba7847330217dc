"""Hostile SMPL-family body files (issue 11): code-running pickles in .pkl and .npz, memory bombs,
malformed trees. Every payload only touches a marker file in tmp_path; the tests assert the
marker does NOT exist and that loading raised ShapeMoveError with a sentence."""
import io
import os
import pickle
import zipfile

import numpy as np
import pytest
import scipy.sparse

from shapemove.core.body.smpl_family import SMPLFamilyBody, read_model_file
from shapemove.core.errors import ShapeMoveError

from synthetic_smpl import synthetic_arrays, write_model


class _Call:
    """Pickles as ``func(*args)``: what an attacker plants in a model file."""

    def __init__(self, func, *args):
        self.func, self.args = func, args

    def __reduce__(self):
        return self.func, self.args


def _payloads(marker):
    touch = f"open({str(marker)!r}, 'w').close()"
    return {
        "exec": _Call(exec, touch),
        "eval": _Call(eval, touch),
        "open": _Call(open, str(marker), "w"),
        "os.system": _Call(os.system, f"touch '{marker}'"),
        "getattr": _Call(getattr, 0, "real"),
        "np.save": _Call(np.save, str(marker), np.zeros(1)),
        "sparse.save_npz": _Call(scipy.sparse.save_npz, str(marker), scipy.sparse.csr_matrix(np.eye(2))),
    }


@pytest.mark.parametrize("name", list(_payloads("x")))
def test_pkl_payload_never_runs(tmp_path, name):
    marker = tmp_path / "marker"
    arrays = synthetic_arrays("smpl", 10, 0)
    arrays["J_regressor"] = _payloads(marker)[name]
    path = tmp_path / "SMPL_NEUTRAL.pkl"
    path.write_bytes(pickle.dumps(arrays, protocol=2))
    with pytest.raises(ShapeMoveError, match="refused to load"):
        SMPLFamilyBody.load(path)
    assert not marker.exists()


def test_pkl_payload_at_top_level_and_protocol_5(tmp_path):
    marker = tmp_path / "marker"
    for proto in (0, 2, 5):
        path = tmp_path / "SMPL_NEUTRAL.pkl"
        path.write_bytes(pickle.dumps(_payloads(marker)["exec"], protocol=proto))
        with pytest.raises(ShapeMoveError, match="refused to load (__builtin__|builtins).exec"):
            read_model_file(path)
    assert not marker.exists()


def test_npz_object_array_never_unpickled(tmp_path):
    marker = tmp_path / "marker"
    arrays = synthetic_arrays("smpl", 10, 0)
    arrays["J_regressor"] = np.array([_payloads(marker)["exec"]], dtype=object)
    path = tmp_path / "SMPL_NEUTRAL.npz"
    np.savez(path, **arrays)
    with pytest.raises(ShapeMoveError, match="J_regressor is a pickled Python object"):
        SMPLFamilyBody.load(path)
    assert not marker.exists()
    # an object array under a key we do not read is never touched; a pickled optional gender is skipped
    arrays = synthetic_arrays("smpl", 10, 0)
    np.savez(path, **arrays, extra=np.array([_payloads(marker)["open"]], dtype=object),
             gender=np.array([_payloads(marker)["open"]], dtype=object))
    assert SMPLFamilyBody.load(path).name == "smpl-neutral"
    assert not marker.exists()


def _pickle_ops(*parts: bytes) -> bytes:
    return b"\x80\x02" + b"".join(parts) + b"."


def test_pkl_allocation_bombs_refused(tmp_path):
    path = tmp_path / "SMPL_NEUTRAL.pkl"
    # numpy.ndarray((10**6, 10**6)) called directly: 8 TB
    path.write_bytes(_pickle_ops(b"cnumpy\nndarray\n", b"(J\x40\x42\x0f\x00J\x40\x42\x0f\x00t", b"\x85R"))
    with pytest.raises(ShapeMoveError, match="could not read body model file"):
        read_model_file(path)
    # _reconstruct(ndarray, (10**12,), b'f') : the array constructor with a huge shape
    path.write_bytes(_pickle_ops(b"cnumpy.core.multiarray\n_reconstruct\n", b"(cnumpy\nndarray\n",
                                 b"\x8a\x05\x00\x10\xa5\xd4\xe8\x85", b"U\x01f", b"tR"))
    with pytest.raises(ShapeMoveError, match="unexpected array constructor"):
        read_model_file(path)


def test_sparse_with_huge_shape_or_bad_indices(tmp_path):
    arrays = synthetic_arrays("smpl", 10, 0)
    path = tmp_path / "SMPL_NEUTRAL.pkl"
    m = scipy.sparse.csc_matrix(arrays["J_regressor"])
    m._shape = (10**7, 10**7)  # toarray() would ask for 800 TB
    path.write_bytes(pickle.dumps({**arrays, "J_regressor": m}, protocol=2))
    with pytest.raises(ShapeMoveError, match="too large"):
        read_model_file(path)
    m = scipy.sparse.csc_matrix(arrays["J_regressor"])
    m.indices = m.indices + 10**6  # out-of-range row indices: C code would write outside the array
    path.write_bytes(pickle.dumps({**arrays, "J_regressor": m}, protocol=2))
    with pytest.raises(ShapeMoveError, match="could not read body model file"):
        read_model_file(path)


def test_npz_header_declaring_huge_array(tmp_path):
    """A 1 KB .npz whose header declares a 2.4 TB shapedirs is refused before reading data."""
    arrays = synthetic_arrays("smpl", 10, 0)
    path = tmp_path / "SMPL_NEUTRAL.npz"
    np.savez(path, **{k: v for k, v in arrays.items() if k != "shapedirs"})
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": (10**8, 3, 1000)})
    with zipfile.ZipFile(path, "a") as zf:
        zf.writestr("shapedirs.npy", buf.getvalue() + b"\0" * 64)
    assert path.stat().st_size < 3_000_000
    with pytest.raises(ShapeMoveError, match="MB, more than any SMPL-family model"):
        read_model_file(path)


def test_oversized_pkl_refused_before_reading(tmp_path):
    path = tmp_path / "SMPL_NEUTRAL.pkl"
    with open(path, "wb") as fh:  # sparse file: 500 MB declared, nothing written
        fh.truncate(500 * 2**20)
    with pytest.raises(ShapeMoveError, match="SMPL-family .pkl files larger than 400 MB are refused"):
        read_model_file(path)


@pytest.mark.parametrize("break_it, match", [
    (lambda a: a["kintree_table"].__setitem__((0, 3), 5), "every parent must come before its child"),
    (lambda a: a["v_template"].__setitem__((0, 0), np.nan), "NaN, infinite"),
    (lambda a: a.__setitem__("weights", np.full(a["weights"].shape, "x")), "not numbers|non-numeric"),
])
def test_malformed_arrays(tmp_path, break_it, match):
    arrays = synthetic_arrays("smpl", 10, 0)
    break_it(arrays)
    path = tmp_path / "SMPL_NEUTRAL.npz"
    np.savez(path, **arrays)
    with pytest.raises(ShapeMoveError, match=match):
        SMPLFamilyBody.load(path)


def test_smplx_tree_cycle_does_not_hang(tmp_path):
    """Finger joints whose parents point at each other used to loop forever in to_24_joints."""
    arrays = synthetic_arrays("smplx", 10, 0)
    arrays["kintree_table"][0, 30], arrays["kintree_table"][0, 31] = 31, 30
    path = tmp_path / "SMPLX_NEUTRAL.npz"
    np.savez(path, **arrays)
    with pytest.raises(ShapeMoveError, match="every parent must come before its child"):
        SMPLFamilyBody.load(path)


def test_genuine_chumpy_pickle_still_loads(tmp_path):
    a = write_model(tmp_path / "basicModel_m.pkl", chumpy=True)
    body = SMPLFamilyBody.load(tmp_path / "basicModel_m.pkl")
    np.testing.assert_allclose(body.v_template.numpy(), a["v_template"], atol=1e-6)
