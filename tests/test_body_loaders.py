"""One OpenBody reader for both views of the body: the torch ``OpenBody`` and Blender's numpy
``BodyArrays`` accept and refuse the same files, and compute the same shapes from them."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.body.body_arrays import load_body_arrays, load_openbody_arrays
from shapemove.core.body.openbody import OpenBody
from shapemove.core.body.openbody_asset import DEFAULT_PATH, FORMAT_VERSION, MODEL_ID, read_openbody
from shapemove.core.constants import is_openbody
from shapemove.core.errors import ShapeMoveError
from shapemove.core.scene.bodies import load_body


def _asset_copy(tmp_path, **changes):
    with np.load(DEFAULT_PATH) as z:
        data = {k: z[k] for k in z.files}
    data.update(changes)
    path = tmp_path / "openbody.npz"
    np.savez(path, **data)
    return path


@pytest.mark.parametrize("change, match", [
    ({"format_version": np.int32(FORMAT_VERSION + 1)}, "format"),
    ({"model_id": np.array("openbody-v0")}, "expected " + MODEL_ID),
    ({"joint_names": np.array(["pelvis"] * 24)}, "SMPL order"),
    ({"faces": np.array([[0, 1, 10 ** 7]])}, "faces"),
])
def test_both_views_refuse_the_same_bad_asset(tmp_path, change, match):
    path = _asset_copy(tmp_path, **change)
    for load in (OpenBody.load, load_openbody_arrays, read_openbody):
        with pytest.raises(ShapeMoveError, match=match):
            load(path)


def test_both_views_compute_the_same_body(openbody):
    arrays = load_body_arrays("openbody")
    assert arrays.name == openbody.name == MODEL_ID and is_openbody(arrays.name)
    betas = np.random.default_rng(3).normal(0, 1, (2, 10))
    np.testing.assert_allclose(arrays.rest_joints(betas), openbody.rest_joints(torch.as_tensor(betas)).numpy(), atol=2e-5)
    np.testing.assert_allclose(arrays.rest_vertices(betas), openbody.rest_vertices(torch.as_tensor(betas)).numpy(), atol=2e-5)
    # and both are the asset's linear shape space: template + shapedirs . betas
    with np.load(DEFAULT_PATH) as z:
        v = z["v_template"] + np.einsum("vcb,b->vc", z["shapedirs"], betas[0])
    np.testing.assert_allclose(arrays.rest_vertices(betas[0])[0], v, atol=1e-9)


def test_the_test_body_is_not_a_product_body_id():
    with pytest.raises(ShapeMoveError, match="capsule-v1"):
        load_body("capsule-v1")
    assert not is_openbody("capsule-v1") and not is_openbody(None) and is_openbody("openbody-v2")
