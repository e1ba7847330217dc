"""Captured takes compete with the T5's samples and play as performed (generation/captured_takes.py)."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from shapemove.core.data.motion_library import MotionLibrary
from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.captured_takes import ACTION_BONUS, TakePool, action_credit, busiest_start, hold, mirrored

pytestmark = pytest.mark.usefixtures("one_thread")

KICK = "a person does a front kick with the left leg"


def lift(y) -> float:
    return float(np.max(y) - np.min(y))


def _rot(n, seed=0):
    from shapemove.core.geometry.rotations import axis_angle_to_matrix

    return axis_angle_to_matrix(np.random.default_rng(seed).normal(0, 0.3, (n, 24, 3))).astype(np.float32)


def test_hold_mirror_and_busiest_window():
    rot, root = _rot(10), np.cumsum(np.full((10, 3), 0.01, np.float32), 0)
    con = np.zeros((10, 4), np.uint8)
    con[-1, 1] = 1
    r, t, c = hold(rot, root, con, 25)
    assert len(r) == len(t) == len(c) == 25
    assert np.array_equal(r[10:], np.repeat(rot[-1:], 15, 0)) and np.array_equal(t[24], root[-1])
    assert (c[10:] == [0, 1, 0, 0]).all()                         # the last frame's contacts held
    con[-1] = 0
    assert (hold(rot, root, con, 12)[2][10:] == 1).all()           # none at the end: both feet down
    assert (hold(rot, root, con, 12, stands=False)[2][10:] == 0).all()   # a sit's feet stay where they are
    m = mirrored(*mirrored(rot, root, con))
    assert np.allclose(m[0], rot, atol=1e-5) and np.allclose(m[1], root) and np.array_equal(m[2], con)
    assert np.allclose(mirrored(rot, root, con)[1][:, 0], -root[:, 0])
    # a take standing still but for frames 100-139: a 40-frame window starts where it moves
    still = np.repeat(_rot(1), 300, 0)
    still[100:140] = _rot(40, 1)
    starts = {busiest_start(still, 40, seed) for seed in range(6)}
    assert starts <= {80, 100} and 100 in starts


def _take(i, action, n=30):
    return {"poses": np.zeros((n, 24, 3)), "root": np.zeros((n, 3)), "contacts": np.ones((n, 4), np.uint8),
            "betas": np.zeros(10), "fps": 20, "clip_id": f"t{i}", "action": action, "source": f"take {i}",
            "licence": "CC0 (test)", "captions": [f"a person does {action} {i}"]}


def test_the_pool_offers_takes_of_the_asked_action_and_the_nearest_captions(openbody):
    actions = ["kick"] * 8 + ["walk"] * 8 + ["wave"] * 4
    lib = MotionLibrary.from_takes([_take(i, a) for i, a in enumerate(actions)])
    unit = lambda v: np.asarray(v, np.float32) / np.linalg.norm(v)  # noqa: E731
    by_action = {"kick": unit([0.6, 0.8, 0, 0]), "walk": unit([0, 0, 1, 0]), "wave": unit([0.95, 0.31, 0, 0])}
    pool = TakePool(openbody, lib)
    pool.set_vectors(np.stack([by_action[a] for a in actions]))   # the waves' captions nearest to the prompt
    text = np.array([1.0, 0, 0, 0], np.float32)
    picks = [pool.nearest(text, "kick", seed) for seed in range(8)]
    for p in picks:
        assert len(p) == 5 and len(set(p)) == 5
        assert sorted(actions[i] for i in p) == ["kick"] * 3 + ["wave"] * 2   # the asked action, the nearest captions
    assert len({tuple(p) for p in picks}) > 1                      # the seed varies which compete
    plain = pool.nearest(text, None, 0)       # no action named: the takes whose captions say the prompt
    assert sorted(plain) == [16, 17, 18, 19]  # the waves (0.95), not the kicks (0.6) nor the walks (0)
    assert pool.take(3)["provenance"] == "captured: take 3 (CC0)"


def test_a_take_that_would_not_compete_gives_its_place_to_another(openbody):
    """The same pool: with every take competing the draw is the one without the test; kicks 0-3
    out (a plain jog's slow takes), the seed's three kicks are all from 4-7, drawn in the places
    of those left out, and the nearest captions' places too are given to waves that compete; with
    only one kick competing, only it is offered of the kicks (none beyond the takes of the action)."""
    actions = ["kick"] * 8 + ["walk"] * 8 + ["wave"] * 4
    lib = MotionLibrary.from_takes([_take(i, a) for i, a in enumerate(actions)])
    unit = lambda v: np.asarray(v, np.float32) / np.linalg.norm(v)  # noqa: E731
    by_action = {"kick": unit([0.6, 0.8, 0, 0]), "walk": unit([0, 0, 1, 0]), "wave": unit([0.95, 0.31, 0, 0])}
    pool = TakePool(openbody, lib)
    vectors = np.stack([by_action[a] for a in actions])
    vectors[:8] += np.linspace(0, 0.01, 8)[:, None]   # kicks 7, 6, ... nearest first
    pool.set_vectors(vectors)
    text = np.array([1.0, 0, 0, 0], np.float32)
    for seed in range(6):
        assert pool.nearest(text, "kick", seed, competes=lambda i: True) == pool.nearest(text, "kick", seed)
        tested = []
        drawn = pool.nearest(text, "kick", seed, competes=lambda i: tested.append(i) or i >= 4)
        kicks = [i for i in drawn if actions[i] == "kick"]
        assert len(drawn) == 5 and len(kicks) == 3 and all(i >= 4 for i in kicks), (seed, drawn)
        assert len(tested) == len(set(tested))                     # each take tested once
        one = pool.nearest(text, "kick", seed, competes=lambda i: i == 5 or actions[i] == "wave")
        assert [i for i in one if actions[i] == "kick"] == [5] and all(actions[i] in ("kick", "wave") for i in one)


def test_a_take_of_another_action_than_the_words_name_does_not_compete():
    assert action_credit("kick", "kick") == ACTION_BONUS
    assert action_credit("jump", "jump forward") == ACTION_BONUS        # a specific form of the asked action
    assert action_credit("jump forward", "jump") is None                 # not the other way round
    assert action_credit("sit", "lie down") is None                      # no sit take: a lying-down take is not one
    assert action_credit(None, "lie down") == 0.0 and action_credit("sit", "") == 0.0   # nothing named, no label
    assert action_credit("walk", "sneak") == ACTION_BONUS and action_credit("walk", "walk backward") is None
    assert action_credit("walk backward", "walk backward") == ACTION_BONUS   # a backward walk only asked by name
    for generic, turning in (("jump", "spin jump"), ("spin", "spin jump"), ("kick", "spin kick"), ("turn", "cartwheel")):
        assert action_credit(generic, turning) is None                   # no turn the words do not ask
        assert action_credit(turning, turning) == ACTION_BONUS


def test_sitting_down_plays_a_lie_down_to_where_it_sits():
    """No take of the data sits down; every lie-down sits on the floor on its way down, and those
    that settle there are offered (``TakePool.stands_in``). "an old man
    sits down slowly" walked 9 m (a retrieved elderly walk) and "he sits" bobbed into a crouch and
    stood up again: now a lie-down take plays to its sit and holds it, the pelvis on the floor and the
    trunk up, the feet where the take has them (planting them on the floor pulled the legs 12 cm)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    # every seed offers a take that sits: "a man sits on a chair and crosses his legs" (seed 0) had drawn
    # only lie-downs that never settle where they sit, and a generated sample bobbed and stood again
    offered = [i for i in range(len(gen.pool)) if gen.pool.actions[i] == "lie down"]
    settled = [i for i in offered if gen.pool.stands_in(i, "sit")]
    assert 0 < len(settled) < len(offered)
    for seed in range(3):
        drawn = gen.pool.nearest(gen._embed_texts(["a man sits on a chair and crosses his legs"])[0], "sit", seed)
        sits = [i for i in drawn if gen.pool.actions[i] == "lie down"]
        assert sits and set(sits) <= set(settled), (seed, drawn)
    for prompt, seed in (("an old man sits down", 0), ("he sits", 1), ("a man sits on a chair and crosses his legs", 0)):
        m = gen.generate_batch([Request(prompt, seconds=4, seed=seed)])[0]
        assert "lieDownFloor" in m.provenance and m.provenance.endswith("its sit on the floor"), m.provenance
        root, head = m.joints[:, 0, 1], m.joints[:, 15, 1]
        assert root[-1] < 0.35 * root[0]                                # down on the floor
        assert head.min() > 0.5 and head[-1] - root[-1] > 0.4           # sitting up, never lying
        assert np.ptp(m.joints[-5:], axis=0).max() < 5e-3                # the sit held (bk 008 sits 0.2 s from the end)
        assert m.ik_error_cm < 3.0
        assert np.linalg.norm(m.joints[-1, 0, [0, 2]] - m.joints[0, 0, [0, 2]]) < 1.0   # where it stood


def test_a_gesture_with_a_sit_is_made_seated():
    """"a man sits down while waving" played the sit alone; "a woman sits down and waves" sat, then
    stood up again to wave. The sit is the legs of two things at once: a lie-down played to its sit,
    the wave's arms on its chest, swinging above the shoulders while the pelvis is on the floor."""
    from shapemove.core.eval.action_signatures import signatures
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    for prompt in ("a man sits down while waving", "a woman sits down and waves"):
        m = gen.generate_batch([Request(prompt, seconds=4, seed=0)])[0]
        legs, arms = m.provenance.split("; ")
        assert "lieDownFloor" in legs and legs.endswith("its sit on the floor") and "wave" in arms, m.provenance
        root = m.joints[:, 0, 1]
        assert root[-1] < 0.35 * root[0] and m.joints[-20:, 15, 1].min() > 0.5   # seated, head up
        assert signatures(m.joints[-40:])["wave"]                             # waving, seated
        assert m.part_prompts[0].endswith("sits down") and m.segment_bounds is None


def test_a_lie_down_after_a_sit_goes_on_from_the_seat():
    """"a man sits on the floor, then lies down": the lie-down segment started standing, so the body
    rose from the floor between the two. A lie-down after a segment that ends seated plays a
    captured lie-down from where it sits: the pelvis stays on the floor from the sit to the end,
    and the head ends down. Regenerating that segment keeps it so."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.stitched_timeline import regenerate_stitched

    gen = Generator(None)
    m = gen.generate_batch([Request("a man sits on the floor, then lies down", seed=0)])[0]
    first, second = m.provenance.split("; ")
    assert first.endswith("its sit on the floor") and second.endswith("from its sit on the floor"), m.provenance
    (s0, e0), (s1, e1) = m.segment_bounds
    root, head = m.joints[:, 0, 1], m.joints[:, 15, 1]
    seated = int(np.argmax(root < 0.35 * root[0]))                 # where the sit reaches the floor
    assert seated < e0 and root[seated:].max() < 0.5 * root[0]       # never up again
    assert head[-5:].mean() < 0.35 * head.max()                      # lying at the end
    again = regenerate_stitched(gen, m, 1, seed=5)
    assert again.provenance.split("; ")[1].endswith("from its sit on the floor")
    assert again.joints[seated:, 0, 1].max() < 0.5 * root[0]


@pytest.fixture(scope="module")
def kick_model(tiny_dataset, tmp_path_factory):
    """The default model with the library of the tiny dataset's takes (train + val)."""
    from shapemove.core.data.library_build import build_library
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR
    from shapemove.core.model_files import add_to_manifest

    d = tmp_path_factory.mktemp("model") / "m"
    shutil.copytree(DEFAULT_MODEL_DIR, d, ignore=shutil.ignore_patterns("library.npz"))
    build_library(tiny_dataset, d / "library.npz", tma_file=d / "tma" / "tma.pt")
    add_to_manifest(d, [d / "library.npz"])   # the copied manifest lists the shipped library
    return d


def test_a_captured_kick_competes_and_plays_as_performed(kick_model, tiny_dataset, openbody):
    from shapemove.core.generation.animate import Animation, animate
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(kick_model, body=openbody)
    m = gen.generate_batch([Request(KICK, seconds=4, seed=0)])[0]
    assert m.provenance.startswith("captured: ") and m.tokens is None and m.num_frames == 80
    src = np.load(tiny_dataset / "new_joints" / "HDM_bd_kickLFront1Reps_001_120.npy")
    assert lift(src[:, 7, 1]) > 0.8
    assert lift(m.joints[:, 7, 1]) >= 0.8 * lift(src[:, 7, 1]) and lift(m.joints[:, 8, 1]) < 0.5 * lift(m.joints[:, 7, 1])
    right = gen.generate_batch([Request("a person does a front kick with the right leg", seconds=4, seed=0)])[0]
    assert lift(right.joints[:, 8, 1]) > 2 * lift(right.joints[:, 7, 1])      # the right foot kicks
    assert "kickLFront" not in right.provenance or right.provenance.endswith(", mirrored")   # a left kick mirrored
    # the edits apply to a captured take
    for anim in (Animation(in_place=True), Animation(speed=1.5), Animation(stretch=3.0)):
        e = animate(gen, Request(KICK, seconds=4, seed=0), anim)
        assert e.provenance == m.provenance and e.num_frames > 20 and np.isfinite(e.joints).all() and lift(e.joints[:, 7, 1]) > 0.5 * lift(src[:, 7, 1])
    with pytest.raises(ShapeMoveError, match="travels"):   # a kick on the spot follows no path: a sentence
        animate(gen, Request(KICK, seconds=4, seed=0), Animation(path=[[0, 0], [0, 2], [2, 2]]))
    held = animate(gen, Request(KICK, seconds=4, seed=0), Animation(in_place=True))
    assert np.ptp(held.joints[:, 0, [0, 2]], axis=0).max() < 1e-3
    stop = gen.generate_batch([Request("a person kicks with the left leg and stops", seconds=4, seed=0)])[0]
    assert stop.num_frames == 80 and np.isfinite(stop.joints).all()
    lib = MotionLibrary.load(kick_model / "library.npz")   # caption vectors made at load (another TMA) are the file's
    again = TakePool(openbody, lib, gen.pool.embed)
    again.set_vectors(None)
    assert lib.vectors.shape == again.vectors.shape and np.abs(again.vectors - lib.vectors).max() < 3e-3
    gen.set_captured(False)   # --no-library: generation only
    off = gen.generate_batch([Request(KICK, seconds=4, seed=0)])[0]
    assert off.provenance == "generated" or off.provenance.startswith("generated from the codes")
    assert off.tokens is not None


def test_the_users_library_kick_rises_as_captured(mocap_root, tmp_path, capsys):
    """The library kick case: four HDM05 bd front kicks with one caption, ``generate --library``
    with that caption: the kicking (left) ankle rises at least 0.8x as high as in the capture."""
    from shapemove.cli import main
    from shapemove.core.generation.retarget import source_joints
    from shapemove.core.scene.motion_file import load_motion

    lib = tmp_path / "kicks"
    lib.mkdir()
    src = mocap_root / "hdm05" / "bd"
    shutil.copy(src / "HDM_bd.asf", lib / "HDM_bd.asf")
    for k in range(1, 5):
        name = f"HDM_bd_kickLFront1Reps_00{k}_120"
        shutil.copy(src / f"{name}.amc", lib / f"{name}.amc")
        (lib / f"{name}.txt").write_text(KICK + "\n")
    out = tmp_path / "kick.npz"
    assert main(["generate", "--prompt", KICK, "--library", str(lib), "--seconds", "4", "--out", str(out)]) == 0
    said = capsys.readouterr().out
    m = load_motion(out)
    assert m.provenance.startswith("captured: ") and m.provenance in said
    kept = [f for f in lib.glob("*.amc") if f.name in m.provenance] or sorted(lib.glob("*.amc"))
    capture = max(lift(source_joints(f)[0][:, 7, 1]) for f in kept) if len(kept) == 1 else \
        min(lift(source_joints(f)[0][:, 7, 1]) for f in kept)
    assert capture > 0.8 and lift(m.joints[:, 7, 1]) >= 0.8 * capture
    out2 = tmp_path / "gen.npz"
    assert main(["generate", "--prompt", KICK, "--library", str(lib), "--no-library", "--seconds", "4",
                 "--out", str(out2)]) == 0
    assert load_motion(out2).provenance.startswith("generated")


def test_two_things_at_once_puts_captured_parts_together(openbody):
    """Each part of a two-things prompt is its own choice among samples and captured takes: the legs
    of a walk take, the arms of a raised-hands take, planted as one motion that another body plants
    again by its rotations."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    r = Request("a man walks forward while raising both hands", seconds=4, seed=3)
    m = gen.generate_batch([r])[0]
    assert m.provenance.startswith("legs: captured: ") and "; arms: captured: " in m.provenance
    assert m.tokens is None and m.planted_take and m.num_frames == 80
    assert m.part_prompts == ("a man walks forward", "a person raising both hands")
    j = m.joints
    travel = float(np.linalg.norm(j[-1, 0, [0, 2]] - j[0, 0, [0, 2]]))
    assert travel > 2.0                                          # a walk's 4 s, not a gesture on the spot
    alone = gen.generate_batch([Request("a person raising both hands", seconds=4, seed=4)])[0]   # the arms' request
    assert m.provenance.endswith("; arms: " + alone.provenance)

    def hands(x):   # each wrist's height over the head: the take raises both and lowers them again
        return np.concatenate([x.joints[:, w, 1] - x.joints[:, 15, 1] for w in (20, 21)])

    assert hands(m).max() > 0.05 and hands(m).min() < -0.5
    assert np.corrcoef(hands(m), hands(alone))[0, 1] > 0.95       # the arms move as the take's, on a walker
    other = gen.redecode(m, np.array([2.0, 1.5, 0, 0, 0, 0, 0, 0, 0, 0], np.float32))
    assert other.num_frames == 80 and other.provenance == m.provenance
    assert np.corrcoef(hands(other), hands(alone))[0, 1] > 0.95
    assert float(np.linalg.norm(other.joints[-1, 0, [0, 2]] - other.joints[0, 0, [0, 2]])) > 2.0
    gen.set_captured(False)   # generation only: both parts from codes, kept for re-decoding
    off = gen.generate_batch([r])[0]
    assert off.tokens is not None and off.arms_tokens is not None and off.provenance == "generated"


def test_a_hop_carries_a_wave_at_once(openbody):
    """A hop leaves the arms free: "a child hops while waving" hops on a hop take's legs and waves a
    wave take's arms (the wave was dropped: one prompt, the hop alone)."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    m = gen.generate_batch([Request("a child hops while waving", seconds=4, seed=0)])[0]
    assert m.part_prompts == ("a child hops", "a person waving")
    legs, arms = m.provenance.split("; arms: ")
    assert "hopBothLegs" in legs and "wave" in arms, m.provenance
    feet = m.joints[:, [7, 8, 10, 11], 1].min(1)
    assert feet.max() - feet.min() > 0.08                       # both feet leave the floor: hops
    wrist = m.joints[:, [20, 21], 1].max(1) - m.joints[:, 15, 1]
    assert (wrist > 0).mean() > 0.5                             # a hand over the head most of the time: waving


def test_an_action_without_takes_draws_on_the_takes_of_its_general_action(openbody):
    """No take of the library is mainly ballet; ballet is a dance (``actions.GENERIC_OF``): the
    dance takes compete for it. A hop has takes of its own, the single hops of HDM05 too short to
    train on (``build.LIBRARY_SPLIT``): "hops forward on both feet" plays one, both feet leaving
    the floor, where the samples alone stand nearly still."""
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None, body=openbody)
    assert "ballet" not in gen.pool.actions and gen._taken("ballet") == "dance" and gen._taken("kick") == "kick"
    assert gen._taken("sit") == "sit"                     # nothing more general (the lie-downs stand in)
    assert gen._taken("shoot") == "throw"                 # a shot at the basket is a throw: HDM05's throwBasketball
    assert gen.pool.actions.count("hop") >= 20 and gen._taken("hop") == "hop"
    m = gen.generate_batch([Request("a man hops forward on both feet", seconds=4, seed=0)])[0]
    assert m.provenance.startswith("captured: ")
    kept = gen.pool.actions[gen.pool.ids.index(m.retrieved_clips[0])]
    assert kept in ("hop", "jump", "jump forward", "spin jump")
    feet = np.minimum(m.joints[:, 10, 1], m.joints[:, 11, 1])
    assert feet.max() - feet.min() > 0.15                 # in the air
    gen.set_captured(False)
    assert gen._taken("ballet") == "ballet"


def test_a_short_gait_take_goes_on_instead_of_standing(openbody):
    """Asked for 8 s, the built-in library's gait takes that cannot loop on two cycles of their own
    go on: HDM05's two sneaking steps (one step of each foot) as the step and its mirror image,
    DeepMimic's stealthy walk (one cycle whose contacts miss the right toe) as one repetition; each
    keeps walking to the end (the root moves in the last second) instead of holding its last pose."""
    from shapemove.core.generation.generate import Generator
    from shapemove.core.generation.track import travel

    pool = Generator(None, body=openbody).pool
    for cid in ("HDM_bd_sneak2StepsLStart_001_120", "deepmimic_stealthy_walk"):
        i = pool.ids.index(cid)
        n = len(pool.take(i)["rotations"])
        w = pool.window(i, 160, 0)
        assert n < 100 and w.looped >= 160 - n - 20 and w.held == 0, (cid, n, w.looped, w.held)
        j = pool.proc.pose_on(w.rotations, w.root, pool.take(i)["betas"], 1.0, w.contacts)
        last = travel(j[-20:])[-1]
        assert last > 0.2, (cid, last)                      # still sneaking on in the last second
