"""Bodies the text describes (issue #25): mass from the mesh, phenotype words on OpenBody's sliders,
stated numbers met on the mesh, conflicts refused, and the eval's targets on generated texts."""
import numpy as np
import pytest

from shapemove.core.body.body_mass import DENSITY_KG_M3, VolumePolynomial, mesh_volume
from shapemove.core.body.measure import format_body, measure
from shapemove.core.body.shape_from_measurements import betas_for_shape_text, betas_from_shape_text, fast_mass
from shapemove.core.errors import ShapeMoveError

CUBE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [2, 3, 7], [2, 7, 6],
                   [1, 2, 6], [1, 6, 5], [0, 4, 7], [0, 7, 3]])


def test_volume_and_its_cubic_in_the_betas(openbody):
    assert mesh_volume(CUBE_V, CUBE_F) == pytest.approx(1.0)
    assert mesh_volume(2.0 * CUBE_V + 5.0, CUBE_F) == pytest.approx(8.0)  # anywhere in space
    # a "shape direction" that stretches the cube along x: volume (1 + b)(1) (1) exactly
    dirs = np.zeros((8, 3, 2))
    dirs[:, 0, 0] = CUBE_V[:, 0]
    dirs[:, 1, 1] = CUBE_V[:, 1]
    poly = VolumePolynomial(CUBE_V, dirs, CUBE_F)
    b = np.array([[0.5, 0.0], [0.5, 1.0], [-0.25, 2.0]])
    np.testing.assert_allclose(poly(b), (1 + b[:, 0]) * (1 + b[:, 1]), rtol=1e-12)
    betas = np.random.default_rng(3).standard_normal((4, 10)) * 1.5
    exact = [measure(openbody, x.astype(np.float32))["mass_kg"] for x in betas]
    np.testing.assert_allclose(fast_mass(openbody, betas), exact, rtol=1e-6)


def test_measure_gives_mass_and_bmi(openbody):
    m = measure(openbody)
    verts = openbody.rest_vertices()[0].numpy()
    assert m["mass_kg"] == pytest.approx(DENSITY_KG_M3 * mesh_volume(verts, openbody.faces), rel=1e-6)
    assert 55 < m["mass_kg"] < 75 and m["bmi"] == pytest.approx(m["mass_kg"] / (m["height_cm"] / 100) ** 2)
    line = format_body(m)
    assert line.startswith("height 169 cm, chest 99 cm") and line.endswith(f"mass {m['mass_kg']:.0f} kg, BMI {m['bmi']:.1f}")


def _read(openbody, text):
    b = betas_for_shape_text(openbody, text)
    p = dict(zip(openbody.phenotype_map.names, openbody.phenotype_map.from_betas(b)))
    return b, p, measure(openbody, b)


def test_words_set_the_sliders_and_the_sexes_differ(openbody):
    _, man, m_man = _read(openbody, "a tall, heavy-set man")
    _, woman, m_woman = _read(openbody, "a tall, heavy-set woman")
    assert man["gender"] == pytest.approx(0.0, abs=1e-6) and woman["gender"] == pytest.approx(1.0, abs=1e-6)
    assert m_man["height_cm"] == pytest.approx(185, abs=0.5) and m_woman["height_cm"] == pytest.approx(185, abs=0.5)
    assert m_man["chest_cm"] - m_man["hip_cm"] > m_woman["chest_cm"] - m_woman["hip_cm"] + 15   # his chest, her hips
    _, old, _ = _read(openbody, "a petite elderly woman")
    assert old["age"] >= 70 and old["gender"] == pytest.approx(1.0)
    _, teen, _ = _read(openbody, "a slim teenage girl")
    assert teen["age"] <= 19 and teen["gender"] == pytest.approx(1.0)
    _, strong, _ = _read(openbody, "a muscular young man")
    assert strong["muscle"] >= 0.8 and strong["age"] <= 30
    assert np.all(betas_from_shape_text(openbody, "an average-sized person") == 0)   # the mean body
    assert betas_for_shape_text(openbody, "a person nods") is None                      # free text: the head's


@pytest.mark.parametrize("text, cm, kg", [("a muscular 188 cm man, 92 kg", 188.0, 92.0),
                                          ("a 6 ft 4, 250 lb man", 76 * 2.54, 250 * 0.45359237),
                                          ("an elderly woman, 1.58 m, 71 kg", 158.0, 71.0),
                                          ("a slim teenage girl, 5'5\", 8 st", 65 * 2.54, 8 * 6.35029318)])
def test_stated_height_and_weight_are_met_on_the_mesh(openbody, text, cm, kg):
    b, p, m = _read(openbody, text)
    assert abs(m["height_cm"] - cm) < 0.3 and abs(m["mass_kg"] - kg) < 0.3, (m["height_cm"], m["mass_kg"])
    if "muscular" in text:
        assert p["muscle"] == pytest.approx(0.85, abs=1e-6) and p["gender"] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("text, match", [
    ("an obese 2 m, 40 kg man", '"obese" means BMI >= 29'),
    ("weighs 900 kg", "no person is 900 kg"),
    ("a 2 cm man", "no person is 2 cm tall"),
    ("a slim man, 110 kg", r"contradicts itself: its body has BMI .*\"slim\" means BMI <= 25"),
    ("a 245 cm, 200 kg woman", "cannot make .* the closest it reaches"),
])
def test_conflicts_and_bodies_out_of_reach_are_refused(openbody, text, match):
    with pytest.raises(ShapeMoveError, match=match):
        betas_for_shape_text(openbody, text)


def test_the_issue_targets_on_generated_texts():
    """Issue #25's targets on the parser + fit path, 30 generated texts per set (the full 200 per set:
    ``python -m shapemove eval shape-words``)."""
    from shapemove.core.eval.shape_words_eval import eval_shape_words

    r = eval_shape_words("auto", texts=30, seed=5, no_shape=False)
    assert r["gender"]["right_pct"] >= 95 and r["gender"]["visible_pct"] >= 95
    assert r["gender"]["woman_minus_man_chest_cm"] < -5 and r["gender"]["woman_minus_man_hip_cm"] > 2
    assert r["age"]["in_band_pct"] >= 90 and r["muscle"]["at_least_0.7_pct"] >= 90
    assert r["numeric"]["both_met_pct"] >= 97 and r["numeric"]["height_err_cm_max"] < 1 and r["numeric"]["mass_err_kg_max"] < 2
    assert r["left_to_head"] == 0 and r["refused_total"] <= 1


def test_cli_body_shape_prints_the_words_sliders_and_body(capsys):
    from shapemove.cli import main

    assert main(["body", "shape", "an elderly woman, 1.58 m, 71 kg"]) == 0
    out = capsys.readouterr().out
    assert "read:    71 kg, 1.58 m, woman, elderly" in out and "gender 1.00, age 75" in out
    assert "height 158 cm" in out and "mass 71 kg, BMI 28.4" in out
    assert main(["body", "shape", "an obese 2 m, 40 kg man"]) == 2
    assert '"obese" means BMI >= 29' in capsys.readouterr().err
