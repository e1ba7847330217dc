"""Foot contacts (detection with hysteresis), planted IK targets, grounding on the mesh soles."""
import numpy as np
import pytest
import torch

from shapemove.core.body.plant import EASE, MIN_EASE, ground_shift, plant_targets, source_floor
from shapemove.core.body.soles import GroundProbe, sole_offsets
from shapemove.core.errors import ShapeMoveError
from shapemove.core.motion.contacts import detect_contacts, runs, to_feature_order


def _standing(openbody, T):
    j = openbody.rest_joints(None)[0, :22].double().numpy()
    return np.repeat(j[None], T, 0)


def test_detects_a_step_with_hysteresis(openbody):
    """Left foot planted 10 frames, swings 10 frames (10 cm up, 1 m/s), planted again; right foot
    planted throughout."""
    T = 30
    j = _standing(openbody, T)
    lift = np.zeros(T)
    lift[10:20] = 0.10 * np.sin(np.linspace(0, np.pi, 12)[1:-1])
    fwd = np.clip((np.arange(T) - 9) * 0.05, 0, 0.5)              # 1 m/s at 20 fps while swinging
    for k in (7, 10):
        j[:, k, 1] += lift
        j[:, k, 2] += fwd
    c = detect_contacts(j)
    assert c.dtype == np.uint8 and c.shape == (T, 4)
    assert c[:, 1].all() and c[:, 3].all()                         # right ankle, right foot
    for col in (0, 2):                                             # left ankle, left foot
        assert runs(c[:, col]) == [(0, 10), (20, 30)]
    # hysteresis: a foot that rises to 5 cm slowly stays in contact (exit at 6 cm) ...
    j2 = _standing(openbody, T)
    j2[:, [7, 10], 1] += np.clip((np.arange(T) - 9) * 0.01, 0, 0.05)[:, None]   # 0.2 m/s up to 5 cm, held
    assert detect_contacts(j2)[:, [0, 2]].all()
    # ... but one that starts there (and never was below 4 cm) is not in contact
    j3 = _standing(openbody, T)
    j3[:, [7, 10], 1] += 0.05
    assert not detect_contacts(j3)[:, 0].any()
    with pytest.raises(ShapeMoveError):
        detect_contacts(np.zeros((5, 10, 3)))
    assert to_feature_order(np.array([1, 2, 3, 4])).tolist() == [1, 3, 2, 4]


def test_plant_targets_fix_contact_joints_on_the_soles(openbody):
    T = 20
    j = _standing(openbody, T) + [0.0, 0.3, 0.0]                   # source floor 30 cm up
    j[:, 7, 0] += np.arange(T) * 0.004                             # left heel slides 4 mm/frame in contact
    c = np.zeros((T, 4), np.uint8)
    c[2:12, 0] = 1
    c[:, 1] = 1
    off = np.array([0.07, 0.07, 0.025, 0.025])
    tgt, floor = plant_targets(j, c, off)
    assert floor == pytest.approx(source_floor(j, c, off))
    rest_h = j[0, [7, 8], 1] - 0.3
    assert floor == pytest.approx(0.3 + float(np.median(np.r_[rest_h[0] - 0.07, rest_h[1] - 0.07])), abs=1e-6)
    planted = tgt[3:10, 7]   # the run 2..11 once eased onto the plant (plant.EASE a frame at its edges)
    assert np.ptp(planted[:, 0]) < 1e-12 and np.ptp(planted[:, 2]) < 1e-12
    assert planted[0, 0] == pytest.approx(j[2:12, 7, 0].mean())
    change = np.linalg.norm(np.diff(tgt[:, 7] - j[:, 7], axis=0), axis=1)   # outside the run the change
    largest = np.linalg.norm(np.diff(j[:, 7], axis=0), axis=1).max()        # moves at the eased rate
    assert change[np.r_[0:2, 11:T - 1]].max() <= max(EASE * largest, MIN_EASE) + 1e-9
    np.testing.assert_allclose(planted[:, 1], 0.07)
    np.testing.assert_allclose(tgt[:, 8, 1], 0.07)
    # after the run the change fades out (at the eased rate), the other joints are untouched
    after = np.linalg.norm((tgt - (j - [0, floor, 0]))[11:, 7], axis=1)
    assert np.all(np.diff(after) <= 1e-12) and after[-1] < 0.5 * after[0] and after[1] > 0
    np.testing.assert_allclose(tgt[:, 0], j[:, 0] - [0, floor, 0])


def test_ground_shift():
    per_foot = np.array([[0.02, 0.10], [0.03, 0.10], [0.10, 0.10], [0.10, 0.01], [0.10, -0.01]])
    lowest_all = per_foot.min(1)
    c = np.zeros((5, 4), np.uint8)
    c[:2, 0] = 1                                                   # left heel: frames 0, 1
    c[3:, 3] = 1                                                   # right toe: frames 3, 4
    s = ground_shift(per_foot, lowest_all, c)
    np.testing.assert_allclose(s, [-0.02, -0.03, -0.02, -0.01, 0.01])   # frame 2 interpolated
    # no contact: one shift for the clip; never under the floor
    s = ground_shift(per_foot, lowest_all, np.zeros((5, 4)))
    np.testing.assert_allclose(s, np.full(5, 0.01))
    c2 = np.zeros((5, 4), np.uint8)
    c2[:, 0] = 1
    s = ground_shift(per_foot, lowest_all, c2)                    # the swinging right foot dips below
    assert (lowest_all + s >= -1e-12).all() and s[4] == pytest.approx(0.01)


def test_soles_match_the_full_mesh(openbody):
    """Sole offsets and the probe's lowest points against the posed full mesh (BodyModel)."""
    betas = torch.tensor([[1.5, -1.0, 0.5, 0, 0, 0.3, 0, 0, 0, -0.5]])
    rest = openbody(betas)
    lab = openbody.skin_weights.argmax(1)
    v = rest.vertices[0].numpy()
    want = [rest.joints[0, j, 1].item() - v[lab == j, 1].min() for j in (7, 8, 10, 11)]
    np.testing.assert_allclose(sole_offsets(openbody, betas)[0].numpy(), want, atol=1e-6)
    assert 0.05 < want[0] < 0.11 and 0.01 < want[2] < 0.05
    # a posed clip: ankles flexed, knees bent, root moving
    T = 6
    g = torch.Generator().manual_seed(0)
    aa = torch.randn(T, 24, 3, generator=g) * 0.3
    transl = torch.randn(T, 3, generator=g) * 0.1
    out = openbody(betas.expand(T, -1), aa, transl)
    probe = GroundProbe(openbody, betas[0].numpy())
    from shapemove.core.geometry.torch_ops import axis_angle_to_matrix

    per_foot, feet, low = probe.lowest(axis_angle_to_matrix(aa.double()).numpy(), transl.numpy())
    mesh = out.vertices[..., 1].numpy()
    foot_l = np.isin(lab, [7, 10])
    foot_r = np.isin(lab, [8, 11])
    np.testing.assert_allclose(per_foot[:, 0], mesh[:, foot_l].min(1), atol=2e-4)
    np.testing.assert_allclose(per_foot[:, 1], mesh[:, foot_r].min(1), atol=2e-4)
    # the candidates hold every vertex that can be lowest: the whole mesh's lowest point
    np.testing.assert_allclose(low, mesh.min(1), atol=5e-4)


def test_ground_shift_caps_flight_of_predicted_contacts():
    """A stretch without contact longer than ``max_flight`` is not a jump: its lowest point goes to
    the floor; a short one keeps its interpolated flight; without the cap (mocap) both keep it."""
    T = 30
    low = np.zeros(T)
    low[5:8] = 0.10            # a 3-frame hop: 10 cm of flight
    low[12:28] = 0.40          # 16 frames "in the air": a decoder that missed the steps
    per_foot = np.stack([low, low], 1)
    c = np.zeros((T, 4), np.uint8)
    c[:5, 0] = c[8:12, 0] = c[28:, 0] = 1
    s = ground_shift(per_foot, low, c, max_flight=10)
    h = low + s
    np.testing.assert_allclose(h[5:8], 0.10)        # the hop stays a hop
    np.testing.assert_allclose(h[12:28], 0.0)       # the long stretch stands on the floor
    h_free = low + ground_shift(per_foot, low, c)
    np.testing.assert_allclose(h_free[12:28], 0.40)  # measured contacts: heights kept (e.g. climbing)


def test_ground_shift_stands_a_long_hover_of_measured_contacts():
    """Measured contacts (no ``max_flight``) that miss a dancer's feet for 2 s: the body, 4 cm over
    the floor set by the contacts around, stands on it, and a leap in that stretch keeps its 0.5 m
    rise over the frames beside it; a climber 0.6 m up most of a stretch stays up; a clip with no
    contact at all, mostly 5 cm up, stands on its lowest points too. Without ``hover`` (the dataset
    builder's grounding) the hover stays."""
    T = 60
    low = np.full(T, 0.04)
    low[:10] = low[50:] = 0.0
    low[27:33] = 0.54                               # the leap: 0.5 m over the hover
    c = np.zeros((T, 4), np.uint8)
    c[:10, 2] = c[50:, 3] = 1
    h = low + ground_shift(np.stack([low, low], 1), low, c, hover=True)
    np.testing.assert_allclose(h[10:27], 0.0)
    np.testing.assert_allclose(h[33:50], 0.0)
    np.testing.assert_allclose(h[27:33], 0.5)
    climb = np.full(T, 0.6)
    climb[:10] = climb[50:] = 0.0
    climb[10:14] = climb[46:50] = 0.05            # stepping up and down: a few low frames
    h = climb + ground_shift(np.stack([climb, climb], 1), climb, c, hover=True)
    np.testing.assert_allclose(h, climb)
    drift = 0.05 + 0.02 * np.sin(np.arange(30) / 3)   # no contact: 3-7 cm up, never on the floor
    h = drift + ground_shift(np.stack([drift, drift], 1), drift, np.zeros((30, 4)), hover=True)
    np.testing.assert_allclose(h, 0.0, atol=1e-12)
    h = low + ground_shift(np.stack([low, low], 1), low, c)   # without: the builder's grounding, held
    np.testing.assert_allclose(h[10:27], 0.04)


def test_ground_shift_keeps_a_jump_longer_than_a_step():
    """A 14-frame flight (0.7 s) rising 0.4 m and falling, between two contacts, is a jump: kept at
    its height (before, every stretch over 10 frames was grounded and a decoded "jumps twice" hopped
    3 cm). Higher than a ballistic flight of that length allows, flat-topped, too long or at the
    clip's end, it is grounded as before."""
    def heights(flight, T=40, s=10):
        low = np.zeros(T)
        low[s:s + len(flight)] = flight
        c = np.zeros((T, 4), np.uint8)
        c[:s, 0] = c[s + len(flight):, 0] = 1
        return low + ground_shift(np.stack([low, low], 1), low, c, max_flight=10)

    t = np.arange(14) + 0.5
    jump = 0.4 * (1 - ((t - 7) / 7) ** 2)             # a parabola: 0.06 m at the ends, 0.4 m at the top
    np.testing.assert_allclose(heights(jump)[10:24], jump)
    np.testing.assert_allclose(heights(2.5 * jump)[10:24], 0.0)            # 1 m in 0.7 s: no jump can
    np.testing.assert_allclose(heights(np.full(14, 0.4))[10:24], 0.0)      # floating, not rising
    t = np.arange(24) + 0.5
    np.testing.assert_allclose(heights(0.4 * (1 - ((t - 12) / 12) ** 2))[10:34], 0.0)   # 1.2 s: too long
    end = heights(jump, T=24)                                              # no landing: grounded
    np.testing.assert_allclose(end[10:24], 0.0)


def test_known_contacts_planted_without_drift_and_body_smoothed(openbody):
    """A decoded clip whose body slides 3 mm/frame and jitters 2 mm, with known contacts (as the
    retargeting path plants the source's): the posed foot in contact stays within 1 mm."""
    from shapemove.core.body.plant import BODY_SMOOTH, plant_motion, smooth_body

    T = 30
    rng = np.random.default_rng(0)
    j = _standing(openbody, T) + [0.0, 0.2, 0.0]                   # source floor 20 cm up
    j[:, :, 2] += np.arange(T)[:, None] * 0.003                     # the whole body skates forward
    j += rng.normal(0, 0.002, j.shape)                              # decoder jitter
    c = np.zeros((T, 4), np.uint8)
    c[2:14, [0, 2]] = 1                                             # left heel + toe down
    c[16:28, [1, 3]] = 1                                            # right heel + toe down
    sm = smooth_body(j, BODY_SMOOTH)
    np.testing.assert_array_equal(sm[:, [7, 8, 10, 11]], j[:, [7, 8, 10, 11]])  # planted joints untouched
    acc = lambda x: np.abs(np.diff(x[:, 0], 2, axis=0)).mean()  # noqa: E731
    assert acc(sm) < 0.4 * acc(j)                                   # pelvis jitter (2nd difference) cut
    b = np.zeros(10, np.float32)
    p = plant_motion(openbody, b, j, c, refine_iters=5, gate=False, max_flight=None, smooth=BODY_SMOOTH)
    np.testing.assert_array_equal(p.contacts, c)                    # known contacts: no gating
    with torch.no_grad():
        out = openbody(torch.as_tensor(b)[None], torch.as_tensor(p.rotations), torch.as_tensor(p.transl))
    posed = out.joints[:, :22].double().numpy()
    for k, jid in enumerate((7, 8, 10, 11)):
        for s, e in runs(c[:, k]):
            xz = posed[s:e, jid][:, [0, 2]]
            inner = xz[1:-1] - xz[1:-1].mean(0)   # a run's first and last frames ease on and off the plant
            assert np.linalg.norm(inner, axis=1).max() < 1e-3, (jid, s, e)   # < 1 mm drift
            assert np.linalg.norm(xz[[0, -1]] - xz[1:-1].mean(0), axis=1).max() < 0.006, (jid, s, e)
    src = j[:, 10, [0, 2]]
    assert np.linalg.norm(src[2:14] - src[2:14].mean(0), axis=1).max() > 0.015     # the input did slide
    # grounded on the mesh: the lowest vertex of the planted foot touches y = 0
    assert float(out.vertices[2:14, ..., 1].min()) == pytest.approx(0.0, abs=2e-3)
