"""The stance foot rolls over its ball (``body/foot_roll.py``): the pitch that keeps the heel within
the leg's reach, and a synthetic stance whose root travels further than a flat planted foot allows,
planted end to end (``plant.plant_motion``): the ball stays pinned, the heel rises and is released,
the toes stay on the floor, the foot keeps its length."""
import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError


@pytest.fixture(scope="module")
def body():
    from shapemove.core.body.load import load_body_model

    return load_body_model(None)


def test_reach_angle_is_the_smallest_pitch_that_reaches():
    from shapemove.core.body.foot_roll import MAX_ROLL, _frame, reach_angle

    pivot = np.zeros(3)
    heel = np.array([0.0, 0.05, -0.14])                 # behind and above the ball (facing +Z)
    e1, e2, L = _frame(heel, pivot)
    assert e2[1] > 0 and abs(e1 @ e2) < 1e-12
    hips = np.array([[0.0, 0.83, -0.10],                # over the heel: in reach flat
                     [0.0, 0.80, 0.25],                 # passed over the ball: must roll
                     [0.0, 0.80, 0.90]])                # out of reach at any pitch
    reach = 0.80
    th = reach_angle(hips, pivot, e1, e2, L, reach)
    assert th[0] == 0.0 and 0 < th[1] < MAX_ROLL and th[2] == MAX_ROLL
    rolled = pivot + L * (np.cos(th[1]) * e1 + np.sin(th[1]) * e2)
    assert np.linalg.norm(hips[1] - rolled) == pytest.approx(reach, abs=1e-9)   # just within reach
    less = pivot + L * (np.cos(th[1] - 0.01) * e1 + np.sin(th[1] - 0.01) * e2)
    assert np.linalg.norm(hips[1] - less) > reach                              # any less is out of reach
    with pytest.raises(ShapeMoveError, match="no length"):
        _frame(pivot, pivot)


def _stance(body, betas, T: int = 24, start: float = -0.15, end: float = 0.42, drop: float = 0.06,
            longer: float = 0.0):
    """A left-foot stance: the body's rest joints, ``drop`` m lower (the stance knee bends),
    carried forward (+Z) from ``start`` to ``end`` m past the planted foot, the left ankle and ball flat on the floor where they
    stand at rest, the left knee bent forward between them (straight where the hip is out of
    reach), the right foot 10 cm up. Contacts: left heel and ball in every frame (a decoder's
    flat-foot stance). ``longer``: the ball that much further forward than the body's foot reaches."""
    with torch.no_grad():
        rest = body.rest_joints(torch.as_tensor(betas)[None])[0].numpy()[:22].astype(np.float64)
    rest[:, 1] -= rest[[7, 10], 1].min() - 0.03                     # the floor just under the feet
    j = np.repeat(rest[None], T, 0)
    j[:, :, 2] += np.linspace(start, end, T)[:, None]
    j[:, :, 1] -= drop
    j[:, [8, 11], 1] += 0.10
    j[:, [7, 10]] = rest[[7, 10]]                                    # planted flat
    j[:, 10, 2] += longer                                            # a decoded foot longer than the body's
    l1, l2 = np.linalg.norm(rest[4] - rest[1]), np.linalg.norm(rest[7] - rest[4])
    v = j[:, 7] - j[:, 1]
    d = np.linalg.norm(v, axis=1, keepdims=True)
    u = v / d
    side = np.array([0.0, 0.0, 1.0]) - u[:, 2:3] * u                 # the knee bends forward
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    cos = ((l1 ** 2 + np.minimum(d, l1 + l2) ** 2 - l2 ** 2) / (2 * l1 * np.minimum(d, l1 + l2))).clip(-1, 1)
    j[:, 4] = j[:, 1] + l1 * (cos * u + np.sqrt(1 - cos ** 2) * side)
    c = np.zeros((T, 4), np.uint8)
    c[:, [0, 2]] = 1
    return j, c, rest


@pytest.mark.parametrize("longer", [0.0, 0.01])
def test_a_stance_that_outruns_a_flat_foot_rolls_over_the_ball(body, longer):
    """``longer``: the decoded foot is 1 cm longer than the body's; the ball lands where the flat
    foot puts it (the pivot), and stays there as the foot rolls."""
    from shapemove.core.body.foot_roll import LIFT_TOL
    from shapemove.core.body.plant import plant_motion
    from shapemove.core.body.soles import GroundProbe
    from shapemove.core.eval.physics import stance_slide
    from shapemove.core.geometry.fk import forward_kinematics

    b = np.zeros(10, np.float32)
    j, c, rest = _stance(body, b, longer=longer)
    p = plant_motion(body, b, j, c, gate=False, max_flight=None)
    with torch.no_grad():
        rj = body.rest_joints(torch.as_tensor(b)[None])[0].numpy()
    pos = forward_kinematics(np.asarray(p.rotations, np.float64), rj, body.parents)[0][:, :22] + p.transl[:, None]
    heel, ball = pos[:, 7], pos[:, 10]
    # the leg cannot reach the flat heel at the end: the hip is out of the leg's reach of it
    leg = np.linalg.norm(rj[4] - rj[1]) + np.linalg.norm(rj[7] - rj[4])
    assert np.linalg.norm(j[-1, 1] - j[-1, 7]) > leg
    # the ball stays pinned through the whole stance (XZ), on its flat height
    assert np.linalg.norm(ball[:, [0, 2]] - ball[0, [0, 2]], axis=1).max() < 1.5e-3
    assert np.ptp(ball[:, 1]) < 5e-3           # the toes do not dip into the floor (the body is not lifted by 17 mm)
    # the heel rises in late stance and moves forward, about the ball: the foot keeps its length
    assert heel[-1, 1] - heel[0, 1] > 0.03 and heel[-1, 2] > heel[0, 2] + 0.005
    assert np.allclose(np.linalg.norm(heel - ball, axis=1), np.linalg.norm(rj[10] - rj[7]), atol=1e-6)
    rise = heel[len(heel) // 2:, 1]
    assert np.all(np.diff(rise) > -1e-3)       # it never comes back down within the stance (by a millimetre:
    # the knee eased at the roll's start lags it by a fraction of a degree)
    # the heel's contact: kept early (flat), released where it rose; a heel in contact is still
    hc = p.contacts[:, 0].astype(bool)
    assert hc[:4].all() and not hc[-4:].any() and p.contacts[:, 2].all()
    assert (heel[hc, 1] - heel[0, 1]).max() <= LIFT_TOL + 1e-3
    released = ~hc & c[:, 0].astype(bool)
    up = heel[released, 1] - heel[0, 1]          # released where its rolled target leaves the floor; the
    assert up.min() > -1e-3 and np.all(np.diff(up) > 0)   # eased knee lets it follow within a millimetre
    mm, _ = stance_slide(pos, p.contacts)
    assert mm.value < 0.5
    # feet on the floor: no point below it by more than 1 cm, the stance foot's sole on it
    per_foot, _, low = GroundProbe(body, b).lowest(p.rotations, p.transl)
    assert low.min() > -0.01 and np.abs(per_foot[:, 0]).max() < 5e-3


def test_a_stance_within_reach_stays_flat(body):
    """The hip never leaves the leg's reach of the flat heel: no roll, every contact kept."""
    from shapemove.core.body.plant import plant_motion

    b = np.zeros(10, np.float32)
    j, c, _ = _stance(body, b, end=0.05)
    p = plant_motion(body, b, j, c, gate=False, max_flight=None)
    np.testing.assert_array_equal(p.contacts, c)


@pytest.mark.parametrize("pitch_deg, roll_deg", [(40.0, 20.0), (25.0, 25.0), (10.0, 35.0)])
def test_rolled_toes_lie_flat_whatever_the_foot_pitch(body, pitch_deg, roll_deg):
    """The leg pass lays a rolled foot's toes flat on the floor, turned to the foot's heading, even
    where the foot is pitched more (or less) than the roll: undoing the roll's angle alone left the
    difference in the toes (a 19-degree excess put them 3 cm under the floor)."""
    from shapemove.core.body.plant import LEGS, pin_feet
    from shapemove.core.geometry.fk import forward_kinematics
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    with torch.no_grad():
        rest = body.rest_joints(torch.zeros(1, 10))[0].numpy().astype(np.float64)
    T = 3
    rot = np.repeat(np.eye(3)[None, None], T, 0).repeat(len(body.parents), 1)
    yaw = axis_angle_to_matrix(np.array([0.0, np.deg2rad(30.0), 0.0]))
    rot[:, 0] = yaw                                                    # the body faces 30 degrees round
    rot[:, 7] = axis_angle_to_matrix(np.array([np.deg2rad(-pitch_deg), 0.0, 0.0]))   # left foot: heel up
    transl = np.zeros((T, 3))
    pos, _ = forward_kinematics(rot, rest, body.parents)
    targets = pos[:, :22].copy()                                       # every joint where it is
    weights = np.zeros((T, 4))
    weights[:, 2] = 1.0                                                # the left ball planted
    toe = np.zeros((T, 2, 3))
    toe[:, 0] = [np.deg2rad(roll_deg), 0.0, 0.0]                       # the roll's own pitch differs
    out = pin_feet(rot, transl, rest, body.parents, targets, weights, toe=toe)
    _, G = forward_kinematics(out, rest, body.parents)
    g = G[:, LEGS[0][3]]
    assert np.allclose(g[:, :, 1], [0.0, 1.0, 0.0], atol=1e-9)         # toes flat: their up is the world's
    heading = np.arctan2(g[:, 0, 2], g[:, 2, 2])
    assert np.allclose(heading, np.deg2rad(30.0), atol=1e-9)           # the foot's heading kept
    right = G[:, LEGS[1][3]]                                           # the other foot: no roll, unchanged
    assert np.allclose(right, forward_kinematics(rot, rest, body.parents)[1][:, LEGS[1][3]])


@pytest.mark.parametrize("roll_deg", [-12.0, 8.0])
def test_a_flat_planted_foot_rolled_onto_its_edge_lies_flat(body, roll_deg):
    """Heel and ball planted: the leg pass lays the sole flat (no roll about the foot's length),
    aimed from the heel's target to the ball's, so the ground shift has no edge to lift the body
    by (a captured squat's foot rolled 1 cm onto its edge settled a frame later: 7.6 mm in a frame
    against 5.0 mm in the take)."""
    from shapemove.core.body.plant import LEGS, pin_feet
    from shapemove.core.geometry.fk import forward_kinematics
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    with torch.no_grad():
        rest = body.rest_joints(torch.zeros(1, 10))[0].numpy().astype(np.float64)
    T = 2
    rot = np.repeat(np.eye(3)[None, None], T, 0).repeat(len(body.parents), 1)
    rot[:, 0] = axis_angle_to_matrix(np.array([0.0, np.deg2rad(-20.0), 0.0]))
    foot_dir = rest[10] - rest[7]
    rot[:, 7] = axis_angle_to_matrix(np.deg2rad(roll_deg) * foot_dir / np.linalg.norm(foot_dir))   # onto an edge
    pos, G0 = forward_kinematics(rot, rest, body.parents)
    targets = pos[:, :22].copy()
    weights = np.zeros((T, 4))
    weights[:, [0, 2]] = 1.0                                           # left heel and ball planted
    out = pin_feet(rot, np.zeros((T, 3)), rest, body.parents, targets, weights)
    p2, G = forward_kinematics(out, rest, body.parents)
    d = p2[:, 10] - p2[:, 7]                                           # the foot's direction, heel to ball
    across = np.cross([0.0, 1.0, 0.0], d)
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    up = G[:, 7][:, :, 1]                                              # the sole's normal
    assert np.abs((up * across).sum(-1)).max() < 1e-9                  # not rolled onto an edge
    assert np.abs((G0[:, 7][:, :, 1] * across).sum(-1)).min() > 0.1    # (as the source was)
    assert np.linalg.norm(p2[:, 10] - targets[:, 10], axis=-1).max() < 2e-3   # the ball on its target
    assert np.abs(G[:, 8] - G0[:, 8]).max() < 1e-9                      # the other foot untouched


@pytest.mark.parametrize("start", [0.15, 0.25])
def test_a_heel_rolling_up_at_once_does_not_snap_the_knee(body, start):
    """A stance that starts with the hip already past the ball (a take cut mid-stride, a jump's
    take-off): the heel rolls up from the first frames. The knee moves no more than 1.5x as far in a
    frame as the source's knee (2.5x when the whole leg followed the rolled heel at once: a
    captured jump's knee leapt 0.135 m against the take's 0.071), while the ball stays pinned."""
    from shapemove.core.body.plant import plant_motion
    from shapemove.core.geometry.fk import forward_kinematics

    b = np.zeros(10, np.float32)
    j, c, rest = _stance(body, b, T=14, start=start, end=start + 0.30)
    p = plant_motion(body, b, j, c, gate=False, max_flight=None)
    with torch.no_grad():
        rj = body.rest_joints(torch.as_tensor(b)[None])[0].numpy()
    pos = forward_kinematics(np.asarray(p.rotations, np.float64), rj, body.parents)[0][:, :22] + p.transl[:, None]
    knee = np.linalg.norm(np.diff(pos[:, 4], axis=0), axis=1).max()
    source = np.linalg.norm(np.diff(j[:, 4], axis=0), axis=1).max()
    assert knee <= 1.5 * source, (knee, source)
    assert np.linalg.norm(pos[:, 10, [0, 2]] - pos[0, 10, [0, 2]], axis=1).max() < 3e-3
    assert pos[-1, 7, 1] - pos[0, 7, 1] > 0.01 or pos[0, 7, 1] - rest[7, 1] > 0.01   # the heel is up
