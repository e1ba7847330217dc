"""Clips of the asked-for action (core/generation/action_clips.py) and the memory's labelled actions
(core/models/motion_memory.py: clip_actions, clips_of_action)."""
import json

import numpy as np
import pytest

from shapemove.core.generation.action_clips import action_clips
from shapemove.core.models.motion_memory import MotionMemory
from shapemove.core.models.text_encoder import load_text_encoder

# clip id -> (captions, labelled actions (main first), number of codes)
CLIPS = {"punch_a": (["A boxer throws punches."], ["punch"], 30),
         "punch_b": (["A man punches the air with both fists."], ["punch"], 8),
         "walk_a": (["Someone walks forward and punches once."], ["walk", "punch"], 40),
         "circle_a": (["A person walks around in a circle."], ["walk", "walk in a circle"], 40),
         "wave_a": (["A person waves a hand."], ["wave"], 25)}


@pytest.fixture(scope="module")
def memory():
    reader = load_text_encoder()
    ids = list(CLIPS)
    mem = MotionMemory.empty()
    mem.add_clips(ids, [CLIPS[c][0] for c in ids], [np.arange(CLIPS[c][2]) % 50 + 10 * i for i, c in enumerate(ids)],
                  reader, actions=[CLIPS[c][1] for c in ids])
    return mem, reader


def test_clips_of_an_action_are_those_labelled_with_it_first(memory):
    mem, _ = memory
    ids = lambda a: sorted(mem.clip_ids[c] for c, _ in mem.clips_of_action(a))  # noqa: E731
    assert ids("punch") == ["punch_a", "punch_b"]        # not the walk whose second label is a punch
    assert ids("walk in a circle") == ["circle_a"]       # nobody's main label: any label counts
    assert ids("kick") == [] and ids("") == []


def test_labels_survive_saving_and_a_memory_without_them_reads_its_captions(memory, tmp_path):
    mem, _ = memory
    mem.save(tmp_path)
    back = MotionMemory.load(tmp_path)
    assert back.clip_actions == [CLIPS[c][1] for c in CLIPS]
    doc = json.loads((tmp_path / "motion_memory.json").read_text())
    del doc["clip_actions"]                               # a memory written before the labels
    (tmp_path / "motion_memory.json").write_text(json.dumps(doc))
    old = MotionMemory.load(tmp_path)
    assert old.clip_actions[0] == ["punch"] and old.clip_actions[4] == ["wave"]
    assert old.clip_actions[3][:2] == ["walk", "walk in a circle"]


def test_action_clips_offer_windows_of_long_clips_and_repeat_short_ones(memory):
    mem, reader = memory
    rows = action_clips(mem, reader, "a fighter throws a jab", "punch", count=2, seed=0, min_codes=20, max_codes=20)
    by = {}
    for cid, codes in rows:
        by.setdefault(cid, []).append(np.asarray(codes))
    assert set(by) == {"punch_a", "punch_b"}
    full = np.asarray(mem.clip_tokens[mem.clip_ids.index("punch_a")])
    assert len(by["punch_a"]) == 3                                   # start, middle, end of 30 codes
    assert np.array_equal(by["punch_a"][0], full[:20]) and np.array_equal(by["punch_a"][-1], full[-20:])
    short = np.asarray(mem.clip_tokens[mem.clip_ids.index("punch_b")])   # 8 codes, played again to 20
    (rep,) = by["punch_b"]
    assert np.array_equal(rep, np.concatenate([short, short, short[:4]]))
    rows = action_clips(mem, reader, "a fighter throws a jab", "punch", 2, 0, min_codes=4, max_codes=5)
    assert [c for cid, c in rows if cid == "punch_b"][0] == list(short[:5])   # long enough now: windows
    assert all(len(c) == 5 for _, c in rows)


def test_the_seed_draws_among_the_nearest_and_nothing_without_the_action(memory):
    mem, reader = memory
    drawn = {action_clips(mem, reader, "someone punches", "punch", 1, s, 4, 8)[0][0] for s in range(12)}
    assert drawn == {"punch_a", "punch_b"}               # one clip a seed, drawn from the 2 nearest
    again = [action_clips(mem, reader, "someone punches", "punch", 1, 5, 4, 8) for _ in range(2)]
    assert again[0] == again[1]                          # the same seed, the same clip
    assert action_clips(mem, reader, "someone kicks", "kick", 2, 0, 4, 8) == []
    assert action_clips(None, reader, "someone punches", "punch", 2, 0, 4, 8) == []
    assert action_clips(MotionMemory.empty(), reader, "x", "punch", 2, 0, 4, 8) == []


def test_generation_takes_the_parts_clips_of_the_planned_action(tmp_path):
    """A two-things prompt's arms come from a clip of its gesture in the model's memory: with a
    memory that holds one short 'wave' clip (2 s of the T5's own codes), the arms track of a 4 s
    motion is that clip played twice, and the motion names the clip."""
    import shutil

    from shapemove.core.generation.generate import Generator, Request, resolve_model_dir
    from shapemove.core.model_files import write_manifest

    model = tmp_path / "model"
    shutil.copytree(resolve_model_dir(None), model)
    for f in (model / "t5").glob("motion_memory.*"):
        f.unlink()
    write_manifest(model)
    gen = Generator(model)
    reader = gen._text_encoder()
    wave = [int(c) for c in gen.tokens_for([Request("a person waves a hand", seconds=2, seed=0, candidates=1)])[0][0]]
    mem = MotionMemory.empty()
    mem.add_clips(["wave_9"], [["a person waves a hand."]], [wave], reader, actions=[["wave"]])
    mem.save(model / "t5")
    write_manifest(model)
    own = Generator(model)
    own.set_captured(False)   # the parts from codes alone (captured takes compete otherwise: test_captured_takes.py)
    # (a sneak: a walk, jog or run would be brought to its typical pace, an edit that keeps no codes)
    m = own.generate_batch([Request("a man sneaks along, waving to a friend", seconds=4, seed=0)])[0]
    assert m.part_prompts is not None and "wave_9" in m.retrieved_clips
    assert list(m.arms_tokens) == (wave * 2)[:20] and len(m.tokens) == 20
    assert m.arms_tokens is not None and m.arms_mirrored in (False, True)
    plain = own.generate_batch([Request("a man jogs along", seconds=4, seed=0, action=None, by_parts=False,
                                        retrieved=0)])[0]
    assert not plain.retrieved_clips                         # no action named, no clip asked for: the T5's
