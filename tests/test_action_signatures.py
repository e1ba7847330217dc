"""The action signatures on hand-made motions: the rest skeleton (standing, floor at 0, facing +z)
moved as each action moves it, every expected value derived from the thresholds by hand."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.eval.action_signatures import (FEET, JUMP_RISE, SIGNED, facing_yaw, flights,
                                                   signatures, signed)
from shapemove.core.motion.skeleton_ops import leg_length

T = 60


@pytest.fixture(scope="module")
def stand(openbody):
    import torch

    j = openbody.rest_joints(torch.zeros(1, 10))[0].numpy()[:22].astype(np.float64)
    j[:, 1] -= j[FEET, 1].min()                   # the lowest foot joint on the floor
    return np.repeat(j[None], T, axis=0)


def _only(sig: dict, *names) -> bool:
    return {k for k, v in sig.items() if v} == set(names)


def test_standing_shows_nothing(stand):
    assert _only(signatures(stand))
    assert 0.75 < leg_length(stand) < 0.95 and abs(facing_yaw(stand)[0]) < 1e-6   # facing +z


def test_a_jump_flies_with_the_pelvis_up_a_run_does_not(stand):
    leg = leg_length(stand)
    j = stand.copy()
    j[25:30, :, 1] += 0.3                          # 5 frames 0.3 m up: feet off, the pelvis 0.3 m over its median
    assert 0.3 >= JUMP_RISE * leg and flights(j, leg) == [(25, 30)]
    assert _only(signatures(j), "jump")
    low = stand.copy()
    low[25:30, :, 1] += 0.1                        # off the floor, but the pelvis only 0.1 m up: a run's flight
    assert 0.1 < JUMP_RISE * leg and flights(low, leg) == [] and _only(signatures(low))
    one = stand.copy()
    one[25, :, 1] += 0.3                           # a single frame is no flight
    assert not signatures(one)["jump"]
    assert signed("jump forward") == signed("hop") == "jump" and signed("walk") is None


def test_a_squat_a_lie_down_and_a_get_up(stand):
    squat = stand.copy()
    squat[20:40, :, 1] *= 0.6                      # the pelvis to 0.6 of where it starts, the head 0.6 of its highest
    assert _only(signatures(squat), "squat")
    lie = stand.copy()
    lie[30:, :, 1] *= 0.1                          # the head ends at 0.1 of its highest, having stood
    assert _only(signatures(lie), "lie down")      # not a squat: the head goes under 0.4 of its highest
    rise = lie[::-1].copy()                        # from lying to standing: the pelvis rises 0.9 x 0.9 m
    assert _only(signatures(rise), "get up")


def test_a_spin_turns_fast_a_slow_turn_does_not(stand):
    def turned(rate):                              # radians a frame about the pelvis
        out = stand.copy()
        for t in range(T):
            c, s = np.cos(rate * t), np.sin(rate * t)
            x, z = out[t, :, 0].copy(), out[t, :, 2].copy()
            out[t, :, 0], out[t, :, 2] = c * x + s * z, -s * x + c * z
        return out

    fast = turned(2 * np.pi / 20)                  # once round a second: 2 pi in 2 s > 1.5 pi
    assert _only(signatures(fast), "spin") and np.ptp(facing_yaw(fast)) > 5 * np.pi
    assert _only(signatures(turned(np.pi / 60)))   # pi / 3 a second: 2 pi / 3 in 2 s


def test_a_kick_lifts_a_foot_high_ahead(stand):
    leg = leg_length(stand)
    kick = stand.copy()
    for k in (7, 10):                               # the left ankle and foot 0.7 L up and 0.5 L ahead
        kick[28:32, k, 1] += 0.7 * leg
        kick[28:32, k, 2] += 0.5 * leg
    assert _only(signatures(kick), "kick")
    back = stand.copy()
    for k in (7, 10):                               # as high behind the body: a run's heel
        back[28:32, k, 1] += 0.7 * leg
        back[28:32, k, 2] -= 0.5 * leg
    assert _only(signatures(back))


def test_jumping_jacks_hop_in_place_hands_up_feet_apart(stand):
    leg = leg_length(stand)
    j = stand.copy()
    for a in (10, 30):                              # two hops 0.1 m up, 4 frames each
        j[a:a + 4, :, 1] += 0.1
        j[a:a + 4, [7, 10], 0] += 0.2 * leg         # the feet apart (the rest stance is 0.37 m wide)
        j[a:a + 4, [8, 11], 0] -= 0.2 * leg
        j[a:a + 4, [20, 21], 1] = j[a, 15, 1] + 0.2  # the wrists over the head
    assert _only(signatures(j), "jumping jacks")
    still = j.copy()
    still[:, :, 2] += np.arange(T)[:, None] * 0.15  # the same going 3 m/s: a run, not in place
    assert not signatures(still)["jumping jacks"]
    assert set(SIGNED) == set(signatures(stand))


def test_real_clips_read_by_their_signatures(tiny_dataset):
    """The tiny dataset's real clips (a few of each archive): its walks, waves, raised hands and runs
    pass no signature that is not theirs, its kicks pass the kick's, most of its waves the wave's."""
    from shapemove.core.eval.signature_accuracy import false_share, own_share, signature_table

    table = {}
    for split in ("train", "val", "test"):
        for a, row in signature_table(tiny_dataset, split).items():
            table.setdefault(a, []).append(row)
    rows = {a: {k: float(np.average([r[k] for r in rs], weights=[r["n"] for r in rs])) for k in SIGNED}
            for a, rs in table.items()}
    for a in ("walk", "wave", "raise hand", "run"):
        if a in rows:
            assert not any(v for k, v in rows[a].items() if k != a), (a, rows[a])
    assert rows["kick"]["kick"] == 1.0 and rows["wave"]["wave"] > 0.5
    assert set(own_share(signature_table(tiny_dataset, "train"))) <= set(SIGNED)
    assert all(0.0 <= v <= 1.0 for v in false_share(signature_table(tiny_dataset, "train")).values())


def test_a_wave_swings_a_raised_wrist_a_raised_hand_holds_it(stand):
    """The left wrist 0.3 m over its shoulder: held there it is a raised hand; swinging 0.1 m each
    way across the body (a 0.75 s period: 7 turns in 3 s) it waves; swinging 2 cm it does not
    (under WAVE_SWING), nor does a wrist swinging below the shoulder."""
    from shapemove.core.eval.action_signatures import WAVE_SWING, turns

    t = np.arange(T)
    raised = stand.copy()
    raised[:, 20, 1] = raised[:, 16, 1] + 0.3
    raised[:, 20, 0] = raised[:, 16, 0] + 0.2
    assert _only(signatures(raised))
    wave, tremble, low = raised.copy(), raised.copy(), raised.copy()
    wave[:, 20, 0] += 0.1 * np.sin(2 * np.pi * t / 15)
    tremble[:, 20, 0] += 0.01 * np.sin(2 * np.pi * t / 15)
    low[:, 20, 0] += 0.1 * np.sin(2 * np.pi * t / 15)
    low[:, 20, 1] = low[:, 16, 1] - 0.3
    assert _only(signatures(wave), "wave") and signed("wave goodbye") == "wave"
    assert 0.02 < WAVE_SWING and _only(signatures(tremble)) and _only(signatures(low))
    assert turns(np.array([0, 1, 0, 1, 0.0]), 0.5) == 3 and turns(np.array([0, 0.4, 0.0]), 0.5) == 0
