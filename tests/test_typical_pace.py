"""A plain gait prompt goes at its gait's typical pace (core/generation/typical_pace.py): the
model folder's table (tools/typical_pace.py: the training data's plain captures on the average
body), a motion more than 3 % above it brought down to it."""
from __future__ import annotations

import json

import numpy as np
import pytest

pytestmark = pytest.mark.usefixtures("one_thread")


def test_which_words_get_a_typical_pace():
    from shapemove.core.generation.typical_pace import plain_gait
    from shapemove.core.plan.words import read_words

    assert plain_gait(read_words("a person walks forward")) == "walk"
    assert plain_gait(read_words("someone is jogging")) == "jog"
    assert plain_gait(read_words("a man runs")) == "run"
    for asked in ("a person walks quickly", "a man runs slowly", "a man walks 3 metres forward",
                  "a person walks in a circle", "a person walks backwards", "a person waves",
                  "takes three steps and stops", "a person jogs in place"):
        assert plain_gait(read_words(asked)) is None, asked
    assert plain_gait(None) is None
    assert plain_gait(read_words("a man runs slowly"), slow=True) == "run"   # slowed from the typical pace
    assert plain_gait(read_words("a person walks quickly"), slow=True) is None


def test_the_table_is_read_bounded_and_checked(tmp_path):
    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.generation.typical_pace import FORMAT, TABLE, load_typical_speeds

    assert load_typical_speeds(tmp_path) == {}
    (tmp_path / TABLE).write_text(json.dumps({"format": FORMAT, "gaits": {"walk": {"speed": 1.2}}}))
    assert load_typical_speeds(tmp_path) == {"walk": 1.2}
    (tmp_path / TABLE).write_text(json.dumps({"format": FORMAT, "gaits": {"walk": {"speed": 120}}}))
    with pytest.raises(ShapeMoveError, match="m/s"):
        load_typical_speeds(tmp_path)
    (tmp_path / TABLE).write_text("[1, 2")
    with pytest.raises(ShapeMoveError, match="not a typical pace table"):
        load_typical_speeds(tmp_path)


@pytest.mark.parametrize("prompt, gait", [("a person jogs", "jog")])
def test_a_plain_jog_goes_at_the_captured_pace(prompt, gait):
    """The default model's jogs ran 2.33 m/s (median, seeds 0-4) against 1.56 m/s for the
    training data's jogs: brought down to it with shorter strides, its cadence kept."""
    from shapemove.core.eval.gait import mean_speed
    from shapemove.core.generation.generate import Generator, Request

    gen = Generator(None)
    if gait not in gen.typical_speeds:
        pytest.skip("the model folder has no typical pace table")
    m = gen.generate_batch([Request(prompt, seed=0)])[0]
    assert 0.95 <= mean_speed(m.joints) / gen.typical_speeds[gait] <= 1.05
    fast = gen.generate_batch([Request("a person jogs quickly", seed=0)])[0]
    assert mean_speed(fast.joints) > 1.2 * gen.typical_speeds[gait]    # a pace asked is kept


def test_a_slow_captured_take_does_not_compete_for_a_plain_gait():
    """The data's strolls won "a man walks" as readily as plain walks (median 0.93x the typical
    pace): a take under 0.95x its typical speed, on its performer's leg, is left out; a pace the
    words ask lets it compete."""
    from shapemove.core.body.load import load_body_model
    from shapemove.core.constants import FPS
    from shapemove.core.generation.captured_takes import Window
    from shapemove.core.generation.typical_pace import SLOW_TAKE, slow_take
    from shapemove.core.plan.words import read_words

    body = load_body_model(None)
    rest = body.rest_joints(__import__("torch").zeros(1, body.num_betas))[0, :24].numpy()
    tall = rest * 1.2                                   # a performer whose leg is 1.2x the average's

    def take(speed, performer, held=0):
        feats = np.zeros((59, 263), np.float32)
        feats[:, 1] = speed / FPS                       # metres a frame, sideways in the root frame
        feats[59 - held:, 1] = 0.0                      # held on its last pose: not walking
        return Window(rotations=np.zeros((60, 24, 3, 3)), root=np.zeros((60, 3)), contacts=np.zeros((60, 4)),
                      rest=performer, features=feats, action="walk", clip_id="x", provenance="captured", held=held)

    speeds = {"walk": 1.2}
    plain = read_words("a man walks")
    assert slow_take(take(1.0, rest), plain, speeds, body)                       # 0.83x
    assert not slow_take(take(1.2 * SLOW_TAKE + 0.01, rest), plain, speeds, body)
    assert slow_take(take(1.2, tall), plain, speeds, body)                      # 1.2 m/s on a 1.2x leg: 0.83x
    assert not slow_take(take(1.2, rest, held=20), plain, speeds, body)         # the held frames do not count
    assert not slow_take(take(1.0, rest), read_words("a man walks slowly"), speeds, body)
    assert not slow_take(take(1.0, rest), read_words("a man waves"), speeds, body)
    assert not slow_take(take(1.0, rest), plain, {}, body)


def test_a_jog_take_at_a_runs_pace_does_not_compete_for_a_plain_jog():
    """DeepMimic's jog goes at 2.8 m/s: for "a man jogs" a take faster than halfway from the jog's
    typical speed to the run's (on its performer's leg) is left out, and for "a man jogs slowly"; one
    at a jog's pace, a walk or a jog asked fast is not."""
    from shapemove.core.body.load import load_body_model
    from shapemove.core.constants import FPS
    from shapemove.core.generation.captured_takes import Window
    from shapemove.core.generation.typical_pace import fast_take
    from shapemove.core.plan.words import read_words

    body = load_body_model(None)
    rest = body.rest_joints(__import__("torch").zeros(1, body.num_betas))[0, :24].numpy()

    def take(speed, performer):
        feats = np.zeros((59, 263), np.float32)
        feats[:, 1] = speed / FPS
        return Window(rotations=np.zeros((60, 24, 3, 3)), root=np.zeros((60, 3)), contacts=np.zeros((60, 4)),
                      rest=performer, features=feats, action="jog", clip_id="x", provenance="captured")

    speeds = {"walk": 1.2, "jog": 1.6, "run": 2.8}          # halfway from the jog to the run: 2.2 m/s
    jogs = read_words("a man jogs")
    assert fast_take(take(2.8, rest), jogs, speeds, body)
    assert fast_take(take(2.25, rest), jogs, speeds, body) and not fast_take(take(2.15, rest), jogs, speeds, body)
    assert not fast_take(take(2.5, rest * 1.2), jogs, speeds, body)     # 2.5 m/s on a 1.2x leg: 2.08 on the average's
    assert not fast_take(take(1.6, rest), jogs, speeds, body)
    assert not fast_take(take(2.8, rest), read_words("a man jogs quickly"), speeds, body)
    assert fast_take(take(2.8, rest), read_words("a man jogs slowly"), speeds, body)   # slowed from a jog's pace
    assert not fast_take(take(2.8, rest), read_words("a man walks"), speeds, body)   # no gait after the walk's
    assert not fast_take(take(2.8, rest), jogs, {"jog": 1.6}, body)


def test_a_take_that_stops_or_circles_is_no_plain_gait():
    """For "a person jogs", a take that stops (1.9 s of jogging held on its last pose for the rest
    of 4 s) or runs around a circle does not compete; one that goes straight does, and a course
    asked for lets a circling take compete."""
    from shapemove.core.generation.captured_takes import Window
    from shapemove.core.generation.typical_pace import unplain_take
    from shapemove.core.plan.words import read_words

    def take(root, held=0):
        n = len(root)
        return Window(rotations=np.zeros((n, 24, 3, 3)), root=np.asarray(root, np.float32), contacts=np.zeros((n, 4)),
                      rest=np.zeros((24, 3)), features=np.zeros((n - 1, 263)), action="jog", clip_id="x",
                      provenance="captured", held=held)

    t = np.arange(80) / 20.0
    line = np.stack([0.1 * np.sin(6 * t), np.full(80, 0.9), 1.5 * t], 1)           # swaying, straight on
    a = 1.5 * t / 2.0                                                               # 1.5 m/s on a 2 m circle
    circle = np.stack([2.0 * (1 - np.cos(a)), np.full(80, 0.9), 2.0 * np.sin(a)], 1)
    stops = line.copy()
    stops[38:] = stops[37]
    plain = read_words("a person jogs")
    assert not unplain_take(take(line), plain)
    assert unplain_take(take(circle), plain)                                        # 172 degrees of a circle
    assert unplain_take(take(stops, held=42), plain)                                # 2.1 of 4 s standing
    assert not unplain_take(take(stops[:42], held=4), plain)                        # the last 0.2 s of 2.1 held
    assert not unplain_take(take(circle), read_words("a person jogs in a circle"))
    assert not unplain_take(take(stops, held=42), read_words("a man kicks"))       # a kick, then standing
    # a gait asked slowly or quickly still goes on: a take that stops does not compete,
    # a circling one may (only the plain gait asks for a straight line)
    for going in ("a person jogs slowly", "she jogs quickly ahead"):
        assert unplain_take(take(stops, held=42), read_words(going)), going
        assert not unplain_take(take(stops[:42], held=4), read_words(going)), going
    assert not unplain_take(take(circle), read_words("a person jogs slowly"))
    assert not unplain_take(take(stops, held=42), read_words("a person jogs and stops"))   # asked to stop


def test_an_edited_take_is_planted_again_on_a_new_body():
    """"a man walks slowly": a captured walk played slower, an edit that keeps no codes, is planted
    again by its own rotations on a taller body (``retarget.replant``), not kept with the old body's
    stride: the same frames, its speed up by the taller leg, its planted feet still."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.loaded_generator import loaded_generator
    from shapemove.core.generation.typical_pace import leg_ratio
    from shapemove.core.motion.root_speed import mean_speed

    gen = loaded_generator(None)
    m = gen.generate_batch([Request("a man walks slowly", seconds=4, seed=0)])[0]
    assert m.tokens is None and m.remakeable and m.planted_take
    tall = np.array([2.0, 1.5, 0, 0, 0, 0, 0, 0, 0, 0], np.float32)
    o = gen.redecode(m, tall)
    assert o.num_frames == m.num_frames and o.provenance == m.provenance
    ratio = mean_speed(o.joints, o.fps) / mean_speed(m.joints, m.fps)
    assert ratio == pytest.approx(leg_ratio(gen.body, m.betas, tall), rel=0.05) and ratio > 1.05

    def slide(x):   # mm a frame of the balls of the feet where planted
        s = []
        for k, j in ((2, 10), (3, 11)):
            on = (x.contacts[1:, k] > 0) & (x.contacts[:-1, k] > 0)
            s += list(np.linalg.norm(np.diff(x.joints[:, j, [0, 2]], axis=0), axis=1)[on])
        return 1000 * float(np.mean(s))

    assert slide(o) < 1.0


def test_the_table_counts_each_capture_once(tiny_dataset, tmp_path):
    """tools/typical_pace.py on a built dataset, before and after ``data mirror`` wrote the mirror
    image of every training clip: the same captures, the same speeds (the mirrors and the composed
    clips doubled the counts and moved the jog's median by 0.01 m/s)."""
    import importlib.util
    import shutil
    from pathlib import Path

    from shapemove.core.data.mirror import mirror_dataset

    spec = importlib.util.spec_from_file_location("typical_pace_tool", Path(__file__).parents[1] / "tools" / "typical_pace.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    data = tmp_path / "built"
    shutil.copytree(tiny_dataset, data)
    before = tool.gait_speeds(data)
    assert sum(len(v) for g in before.values() for v in g.values()) >= 2, before
    assert mirror_dataset(data, verbose=False)                       # mirror images written into train
    assert tool.gait_speeds(data) == before


def test_a_jog_asked_fast_stays_a_jog():
    """"a man jogs quickly" was chosen at 2.7-3.6 m/s, a run's pace: a jog asked fast is brought
    down to no faster than halfway between the jog's and the run's typical speeds; a run or a walk
    asked fast, and a plain jog, keep their own rule."""
    from shapemove.core.generation.typical_pace import fast_gait, paced_target
    from shapemove.core.plan.words import read_words

    speeds = {"walk": 1.19, "jog": 1.56, "run": 2.87}
    assert fast_gait(read_words("a man jogs quickly")) == "jog"
    assert paced_target(read_words("a man jogs quickly"), speeds) == ("jog", pytest.approx(2.215))
    assert paced_target(read_words("the boy does a quick jog"), speeds) == ("jog", pytest.approx(2.215))
    assert paced_target(read_words("a man jogs"), speeds) == ("jog", 1.56)        # typical
    for other in ("a man runs quickly", "a person walks quickly", "a man jogs quickly in a circle",
                  "a man jogs quickly to the left"):
        assert paced_target(read_words(other), speeds) is None, other
    assert paced_target(read_words("a man jogs quickly"), {"jog": 1.56}) is None   # no run in the table


def test_a_quick_jog_goes_faster_than_a_jog_and_slower_than_a_run(openbody):
    """With the default model (seed 0): between the typical jog and the typical run on its body."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.typical_pace import TOLERANCE, body_speed, load_typical_speeds
    from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR
    from shapemove.core.motion.root_speed import mean_speed

    gen = Generator(None, body=openbody)
    m = gen.generate_batch([Request("a man jogs quickly", seconds=4, seed=0)])[0]
    speeds = load_typical_speeds(DEFAULT_MODEL_DIR)
    speed = mean_speed(m.joints, m.fps)
    cap = body_speed((speeds["jog"] + speeds["run"]) / 2, openbody, m.betas)
    assert body_speed(speeds["jog"], openbody, m.betas) < speed <= cap * (1 + TOLERANCE)


def test_the_table_reads_each_capture_once_under_way(tiny_dataset):
    """A capture's speed in the table is its speed over its steady stretch (``steady_span``: HDM05's
    jogs are 4 steps from standing), the whole take's where it has none."""
    import importlib.util
    from pathlib import Path

    import numpy as np

    from shapemove.core.motion.root_speed import mean_speed, steady_span

    spec = importlib.util.spec_from_file_location("typical_pace_tool", Path(__file__).parents[1] / "tools" / "typical_pace.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    found = tool.gait_speeds(tiny_dataset)
    read = []
    for cid in (tiny_dataset / "train.txt").read_text().split():
        path = tiny_dataset / "norm_joints" / f"{cid}.npy"
        if path.is_file():
            j = np.load(path)
            span = steady_span(j) or (0, len(j))
            read.append((cid, mean_speed(j[span[0]:span[1]]), mean_speed(j), span))
    in_table = sorted(v for kinds in found.values() for speeds in kinds.values() for v in speeds)
    assert in_table and all(any(abs(v - r[1]) < 1e-9 for r in read) for v in in_table)
    assert any(abs(v - r[1]) < 1e-9 and r[1] > 1.05 * r[2] for r in read for v in in_table), (read, found)
