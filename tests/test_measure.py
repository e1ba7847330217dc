"""Measurements: the slicing/perimeter routines against analytic answers, then OpenBody."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.body.measure import MEASUREMENTS, contains, cross_section, hull_perimeter, measure, measure_mesh
from shapemove.core.body.model import BodyModel
from shapemove.core.errors import ShapeMoveError

N = 48  # sides of the test prisms


def prism(radius, y0, y1, centre=(0.0, 0.0), rings=9, n=N):
    """Closed triangulated N-gon prism (a cylinder) along Y. Returns vertices (V,3), faces (F,3)."""
    a = 2 * np.pi * np.arange(n) / n
    ys = np.linspace(y0, y1, rings)
    ring = np.stack([centre[0] + radius * np.cos(a), np.zeros(n), centre[1] + radius * np.sin(a)], 1)
    verts = [ring + [0, y, 0] for y in ys]
    faces = []
    for r in range(rings - 1):
        for i in range(n):
            a0, a1 = r * n + i, r * n + (i + 1) % n
            b0, b1 = a0 + n, a1 + n
            faces += [[a0, b0, a1], [a1, b0, b1]]
    base = rings * n
    verts += [np.array([[centre[0], y0, centre[1]], [centre[0], y1, centre[1]]])]
    for i in range(n):  # caps
        faces += [[base, i, (i + 1) % n], [base + 1, (rings - 1) * n + (i + 1) % n, (rings - 1) * n + i]]
    return np.concatenate(verts), np.array(faces)


def ngon_perimeter(radius, n=N):
    return 2 * n * radius * np.sin(np.pi / n)


def test_hull_perimeter_of_a_polygon_and_its_inner_points():
    a = 2 * np.pi * np.arange(N) / N
    pts = 0.15 * np.stack([np.cos(a), np.sin(a)], 1)
    inner = np.random.default_rng(0).uniform(-0.05, 0.05, (30, 2))  # inside: don't change the hull
    assert hull_perimeter(np.concatenate([pts, inner])) == pytest.approx(ngon_perimeter(0.15), rel=1e-9)
    square = np.array([[0, 0], [2, 0], [2, 1], [0, 1], [1, 0.5]])
    assert hull_perimeter(square) == pytest.approx(6.0)
    assert hull_perimeter(np.zeros((2, 2))) == 0.0


def test_cross_section_of_cylinders():
    v1, f1 = prism(0.12, 0.0, 1.0)
    v2, f2 = prism(0.05, 0.2, 0.8, centre=(0.5, 0.1))
    verts, faces = np.concatenate([v1, v2]), np.concatenate([f1, f2 + len(v1)])
    pieces = cross_section(verts, faces, 0.43)
    assert len(pieces) == 2
    big = [p for p in pieces if contains(p, (0.0, 0.0))]
    small = [p for p in pieces if contains(p, (0.5, 0.1))]
    assert len(big) == 1 and len(small) == 1 and big[0] is not small[0]
    assert not contains(big[0], (0.3, 0.0))
    # the section of an N-gon prism is the N-gon: segment lengths add up to its perimeter
    length = np.linalg.norm(big[0][:, 0] - big[0][:, 1], axis=1).sum()
    assert length == pytest.approx(ngon_perimeter(0.12), rel=1e-9)
    assert hull_perimeter(big[0].reshape(-1, 2)) == pytest.approx(ngon_perimeter(0.12), rel=1e-9)
    # slicing exactly through a ring of vertices still gives one closed loop
    assert len(cross_section(v1, f1, 0.5)) == 1
    assert cross_section(v1, f1, 2.0) == []


JOINTS = {  # a stick figure in T-pose, metres
    "pelvis": (0, 0.85, 0), "left_hip": (0.1, 0.8, 0), "right_hip": (-0.1, 0.8, 0), "spine1": (0, 0.95, 0),
    "left_knee": (0.1, 0.45, 0), "right_knee": (-0.1, 0.45, 0), "spine2": (0, 1.05, 0),
    "left_ankle": (0.1, 0.08, 0), "right_ankle": (-0.1, 0.08, 0), "spine3": (0, 1.15, 0),
    "left_foot": (0.1, 0.02, 0.1), "right_foot": (-0.1, 0.02, 0.1), "neck": (0, 1.4, 0),
    "left_collar": (0.07, 1.35, 0), "right_collar": (-0.07, 1.35, 0), "head": (0, 1.5, 0),
    "left_shoulder": (0.2, 1.3, 0), "right_shoulder": (-0.2, 1.3, 0),
    "left_elbow": (0.5, 1.3, 0), "right_elbow": (-0.5, 1.3, 0),
    "left_wrist": (0.75, 1.3, 0), "right_wrist": (-0.75, 1.3, 0),
    "left_hand": (0.85, 1.3, 0), "right_hand": (-0.85, 1.3, 0),
}


class CylinderBody(BodyModel):
    """A trunk cylinder (radius 0.15 m + 0.01 m per beta0) with both arms as thin cylinders at
    chest level, and 24 loose marker vertices the joint regressor picks out."""

    def __init__(self):
        trunk_v, trunk_f = prism(0.15, 0.0, 1.6)
        arms = [prism(0.04, 1.0, 1.25, centre=(x, 0.0)) for x in (0.3, -0.3)]  # hanging arms
        verts = [trunk_v] + [a[0] for a in arms]
        faces, offset = [trunk_f], len(trunk_v)
        for av, af in arms:
            faces.append(af + offset)
            offset += len(av)
        markers = np.array([JOINTS[n] for n in self.joint_names], dtype=np.float64)
        V = offset + 24
        shapedirs = np.zeros((V, 3, 10))
        radial = trunk_v.copy()
        radial[:, 1] = 0
        norms = np.linalg.norm(radial, axis=1, keepdims=True)
        shapedirs[: len(trunk_v), :, 0] = np.where(norms > 0, 0.01 * radial / np.maximum(norms, 1e-12), 0)
        J = np.zeros((24, V))
        J[np.arange(24), offset + np.arange(24)] = 1
        w = np.zeros((V, 24))
        w[:, 0] = 1
        super().__init__(np.concatenate(verts + [markers]), shapedirs, J, w, np.concatenate(faces), name="cylinder")


def test_measure_on_a_constructed_body_with_known_answers():
    body = CylinderBody()
    m = measure(body)
    assert m["height_cm"] == pytest.approx(160.0, abs=1e-4)
    # the hanging arms cut the chest/waist planes but are separate loops: only the trunk counts
    for key in ("chest_cm", "waist_cm", "hip_cm"):
        assert m[key] == pytest.approx(100 * ngon_perimeter(0.15), rel=1e-5), key
    assert m["arm_length_cm"] == pytest.approx(55.0, abs=1e-4)  # 0.30 + 0.25
    assert m["leg_length_cm"] == pytest.approx(80.0, abs=1e-4)  # 0.35 + 0.37 + ankle height 0.08
    batched = measure(body, np.array([[2.0] + [0] * 9, [0.0] * 10]))
    assert batched["waist_cm"][0] == pytest.approx(100 * ngon_perimeter(0.17), rel=1e-5)
    assert batched["waist_cm"][1] == pytest.approx(m["waist_cm"], rel=1e-9)
    with pytest.raises(ShapeMoveError, match="betas"):
        measure(body, np.zeros(3))


def test_measure_mesh_refuses_a_body_upside_down():
    body = CylinderBody()
    j = body.rest_joints()[0].numpy() * [1, -1, 1]
    with pytest.raises(ShapeMoveError, match="shoulders"):
        measure_mesh(body.v_template.numpy(), body.faces, j)


def test_openbody_measurements_are_plausible(openbody):
    m = measure(openbody)
    assert 165 < m["height_cm"] < 180
    assert 85 < m["chest_cm"] < 115 and 65 < m["waist_cm"] < 100 and 85 < m["hip_cm"] < 115
    assert m["waist_cm"] < min(m["chest_cm"], m["hip_cm"])
    assert 40 < m["arm_length_cm"] < 65 and 75 < m["leg_length_cm"] < 100
    # the measurement follows the mesh: scaling the body about the floor scales every number
    v = openbody.rest_vertices()[0].numpy()
    j = openbody.rest_joints()[0].numpy()
    m2 = measure_mesh(1.1 * v, openbody.faces, 1.1 * j)
    for k in MEASUREMENTS:
        assert m2[k] == pytest.approx(1.1 * m[k], rel=0.02), k
    assert m2["mass_kg"] == pytest.approx(1.1 ** 3 * m["mass_kg"], rel=1e-5)   # volume: the cube
    assert m2["bmi"] == pytest.approx(1.1 * m["bmi"], rel=1e-5)                # kg / m^2
