"""Body shape from explicit numbers: the precomputed girth regression against the real mesh
measurement, the fast fit, and numbers no body has refused with a sentence."""
import time

import numpy as np
import pytest

from shapemove.core.body.measure import measure
from shapemove.core.body.shape_from_measurements import (GIRTHS, betas_for_measurements, body_key, fast_measure,
                                                         girth_regression, shape_targets)
from shapemove.core.errors import ShapeMoveError


def test_girth_regression_matches_the_mesh_measurement(openbody):
    reg = girth_regression(openbody)
    assert reg is not None and reg.key == body_key(openbody), "assets/girth_regression.npz is stale: rerun " \
        "tools/build_girth_regression.py"
    b = np.random.default_rng(7).standard_normal((6, 10))  # bodies the regression was not fitted on
    m = measure(openbody, b)
    mesh = np.stack([m[k] for k in GIRTHS], 1)
    err = np.abs(reg.predict(b) - mesh)
    assert err.max() < 2.0 and err.mean() < 0.8, err
    # the cheap measurements are the mesh's own, exactly
    cheap = fast_measure(openbody, b, ["height_cm", "arm_length_cm", "leg_length_cm"])
    np.testing.assert_allclose(cheap, np.stack([m[k] for k in ("height_cm", "arm_length_cm", "leg_length_cm")], 1),
                               atol=1e-3)


def test_fit_to_numbers_is_fast_and_right_on_the_mesh(openbody):
    targets = {"height_cm": 178.0, "waist_cm": 95.0, "chest_cm": 104.0}
    betas_for_measurements(openbody, targets)  # first call prepares the body's arrays
    t0 = time.perf_counter()
    b = betas_for_measurements(openbody, targets)
    ms = 1000 * (time.perf_counter() - t0)
    print(f"fit of 3 measurements: {ms:.1f} ms")
    got = measure(openbody, b)  # checked on the real mesh
    assert abs(got["height_cm"] - 178) < 0.5 and abs(got["waist_cm"] - 95) < 2.0 and abs(got["chest_cm"] - 104) < 2.0
    exact = betas_for_measurements(openbody, targets, exact=True)  # the slow mesh fit lands close by
    assert abs(measure(openbody, exact)["waist_cm"] - 95) < 1.0


def test_a_body_without_regression_uses_the_mesh(openbody):
    import copy

    import torch

    other = copy.deepcopy(openbody)
    with torch.no_grad():
        other.shapedirs[:, 1, 0] *= 1.05  # another shape space
    assert girth_regression(other) is None and girth_regression(openbody) is not None


@pytest.mark.parametrize("text, match", [
    ("a person 5000 cm tall", "no person is 5000 cm tall"),
    ("a man with a waist of 0 cm", "waist 0 cm is outside the plausible range"),
    ("A person standing -170 cm tall", "negative number"),
    ("someone -1.8 m tall", "negative number"),
    ("a woman 999 m tall", "no person is 99900 cm tall"),
    ("a man who weighs 180", "cannot read the number in .* weighs 180"),
])
def test_impossible_numbers_are_refused(text, match):
    with pytest.raises(ShapeMoveError, match=match):
        shape_targets(text)


def test_shape_texts_that_are_read_or_left_to_the_model():
    assert shape_targets("1.9 m tall, waist 100 cm") == {"height_cm": 190.0, "waist_cm": 100.0}
    assert shape_targets("a 39-inch waist, 170-180 cm tall")["waist_cm"] == pytest.approx(99.06)
    assert shape_targets("a tall man")["height_cm"] == 185.0
    assert shape_targets("a man 180 kg, 2 metres") == {"height_cm": 200.0, "mass_kg": 180.0}
    for words in ("a man in his 30s", "a friendly old lady"):   # phenotype words: sliders, no measurement
        assert shape_targets(words) == {}
    for free in ("someone with broad shoulders", "a person nods"):
        assert shape_targets(free) is None  # no numbers, no shape words: the [BETA] head reads it
