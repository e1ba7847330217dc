"""Retrieval as memory (core/models/motion_memory.py and the T5 decoder that reads it)."""
import random

import numpy as np
import pytest
import torch

from shapemove.core.errors import ShapeMoveError
from shapemove.core.models.motion_memory import MotionMemory, family
from shapemove.core.models.shapemove_t5 import ShapeMoveT5, T5Size
from shapemove.core.models.text_encoder import load_text_encoder

CLIPS = {"punch_1": ["A boxer throws punches.", "A man punches the air."],
         "kick_1": ["A person kicks with the left leg."],
         "walk_1": ["Someone walks forward."], "walk_1_mirror": ["Someone walks forward."],
         "wave_1": ["A person waves a hand."]}


@pytest.fixture(scope="module")
def memory():
    reader = load_text_encoder()
    ids = list(CLIPS)
    toks = [np.arange(i, i + 6) % 10 for i in range(len(ids))]
    mem = MotionMemory([], torch.zeros(0, 384), [], [], [])
    mem.add_clips(ids, [CLIPS[c] for c in ids], toks, reader, [family(c) for c in ids])
    return mem, reader


def test_families_join_a_clip_its_copies_and_compositions():
    assert family("dataset-1_walk_001_aug_mirror") == {"dataset-1_walk_001"}
    assert family("parts0_00001_mirror", {"mirror_of": "parts0_00001", "composed_from": ["a_aug", "b"]}) \
        == {"parts0_00001", "a", "b"}


def test_nearest_caption_wins_and_own_family_is_left_out(memory):
    mem, reader = memory
    ids, sims = mem.lookup(reader, ["a fighter throws a jab", "a person strolls ahead"], k=2, max_codes=8)
    first = [mem.clip_ids[int(np.argmax([np.array_equal(ids[b, 0, :6].numpy(), t) for t in mem.clip_tokens]))]
             for b in range(2)]
    assert first[0] == "punch_1" and first[1] in ("walk_1", "walk_1_mirror")
    assert sims[0, 0] > sims[0, 1] > 0 and (ids[:, :, 6:] == -1).all()       # padded beyond 6 codes
    # a walk leaves out itself and its mirror: its nearest neighbour is another action
    near = mem.nearest(torch.nn.functional.normalize(mem.vectors[[mem.texts.index("Someone walks forward.")]], dim=-1),
                       2, [family("walk_1")], random.Random(0))[0]
    assert all(not mem.clip_ids[c].startswith("walk_1") for c, _ in near) and len(near) == 2
    # the null prompt and empty=True give no memory
    ids0, _ = mem.lookup(reader, ["", "a person waves"], k=2, max_codes=8, empty=[False, True])
    assert (ids0 == -1).all()


def test_saved_memory_loads_the_same_and_damage_is_refused(memory, tmp_path):
    mem, reader = memory
    mem.save(tmp_path)
    back = MotionMemory.load(tmp_path)
    assert back.clip_ids == mem.clip_ids and back.texts == mem.texts
    assert all(np.array_equal(a, b) for a, b in zip(back.clip_tokens, mem.clip_tokens))
    a, _ = mem.lookup(reader, ["a man kicks"], 3, 8)
    b, _ = back.lookup(reader, ["a man kicks"], 3, 8)
    assert torch.equal(a, b)
    (tmp_path / "motion_memory.json").write_text('{"texts": [], "clip_ids": []}')
    with pytest.raises(ShapeMoveError, match="do not match"):
        MotionMemory.load(tmp_path)
    (tmp_path / "motion_memory.json").unlink()
    with pytest.raises(ShapeMoveError, match="missing"):
        MotionMemory.load(tmp_path)


def test_decoder_reads_the_memory_and_empty_memory_is_text_only():
    torch.manual_seed(0)
    size = T5Size(d_model=32, d_ff=64, num_layers=1, num_decoder_layers=1, num_heads=2, d_kv=16, dropout_rate=0.0,
                  memory_k=2, memory_codes=4)
    model = ShapeMoveT5.build_minilm(10, size).eval()
    states, mask, seg = torch.randn(1, 5, 384), torch.ones(1, 5, dtype=torch.bool), torch.ones(1, 5, dtype=torch.long)
    dec = torch.tensor([[0, 2, 3]])
    full = torch.tensor([[[5, 6, 7, 8], [9, 10, 11, -1]]])
    other = torch.tensor([[[12, 13, 14, 8], [9, 10, 11, -1]]])
    sims = torch.tensor([[0.8, 0.5]])
    with torch.no_grad():
        enc, m = model.lm.encode(states, mask, seg, full, sims)
        assert enc.shape[1] == 5 + 8 and m.sum() == 5 + 7
        la = model.lm.step(enc, m, dec)[0]
        lb = model.lm.step(*model.lm.encode(states, mask, seg, other, sims), dec)[0]
        assert (la - lb).abs().max() > 1e-3                                    # the memory is read
        empty = torch.full_like(full, -1)
        le = model.lm.step(*model.lm.encode(states, mask, seg, empty, sims), dec)[0]
        lt = model.lm.step(*model.lm.encode(states, mask, seg), dec)[0]
        assert torch.allclose(le, lt, atol=1e-5)                               # no memory = text only


def test_retrieval_seeds_are_the_starts_of_the_nearest_clips(memory):
    from shapemove.core.generation.retrieval_seeds import seed_prefixes, seeded_count

    mem, reader = memory
    rows = seed_prefixes(mem, reader, "a fighter throws a jab", count=2, prefix=3)
    assert rows[0] == mem.clip_tokens[mem.clip_ids.index("punch_1")][:3].tolist() == [0, 1, 2]
    assert len(rows) == 2 and all(len(r) == 3 for r in rows) and rows[1] != rows[0]
    assert seed_prefixes(mem, reader, "a fighter throws a jab", count=2, prefix=6) == []  # clips of 6 codes: none longer
    assert seed_prefixes(None, reader, "a jab", 2, 2) == [] and seed_prefixes(mem, reader, "a jab", 0, 2) == []
    assert [seeded_count(n) for n in (1, 2, 8)] == [0, 1, 4]


def test_per_row_prefixes_decode_as_each_prefix_alone():
    from shapemove.core.models.constrained_decoding import decode

    torch.manual_seed(0)
    size = T5Size(d_model=32, d_ff=64, num_layers=1, num_decoder_layers=1, num_heads=2, d_kv=16, dropout_rate=0.0)
    model = ShapeMoveT5.build_minilm(10, size).eval()
    states, mask, seg = torch.randn(2, 5, 384), torch.ones(2, 5, dtype=torch.bool), torch.ones(2, 5, dtype=torch.long)
    states[1] = states[0]
    with torch.no_grad():
        both = decode(model, (states, mask, seg), 4, 4, temperature=0, prefix_codes=[[1, 2], [7, 3]])
        a = decode(model, (states[:1], mask[:1], seg[:1]), 4, 4, temperature=0, prefix_codes=[1, 2])
        b = decode(model, (states[:1], mask[:1], seg[:1]), 4, 4, temperature=0, prefix_codes=[7, 3])
    assert both.codes == [a.codes[0], b.codes[0]] and both.codes[0] != both.codes[1]
    assert torch.allclose(both.betas[0], both.betas[1], atol=1e-6)  # [BETA] precedes the codes
    with pytest.raises(ValueError, match="one length"):
        decode(model, (states, mask, seg), 4, 4, temperature=0, prefix_codes=[[1, 2], [3]])
