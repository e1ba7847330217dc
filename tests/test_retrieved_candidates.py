"""Real clips retrieved by caption as best-of-N candidates (core/generation/retrieved_candidates.py)
and the judges that must not find a retrieved clip's own take (eval/action_classifier.py)."""
from __future__ import annotations

import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.retrieved_candidates import retrieved_codes, windows
from shapemove.core.models.motion_memory import sentence_vectors

pytestmark = pytest.mark.usefixtures("one_thread")


def test_windows_cut_a_clip_to_the_requested_length():
    c = list(range(30))
    assert windows(c, 5, 40) == [c]                      # fits: the whole clip
    assert windows(c, 31, 40) == []                     # shorter than the least asked for
    w = windows(c, 10, 10)
    assert w == [c[0:10], c[10:20], c[20:30]]           # start, middle, end
    assert windows(list(range(11)), 10, 10) == [list(range(10)), list(range(1, 11))]


@pytest.fixture(scope="module")
def gen():
    from shapemove.core.generation.generate import Generator

    g = Generator(None)
    g.set_captured(False)   # the retrieval memory's candidates, which these tests are about
    return g


@pytest.fixture()
def memory(gen):
    """A memory of three clips of the default model's own tokens: a walk and two punches."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.models.motion_memory import MotionMemory

    walk = gen.tokens_for([Request("a person walks forward", seconds=4, seed=0, candidates=1)])[0][0]
    punch = gen.tokens_for([Request("a person throws punches", seconds=6, seed=0, candidates=1)])[0][0]
    mem = MotionMemory.empty()
    mem.add_clips(["walk_1", "punch_1", "punch_1_mirror"],
                  [["a person walks forward."], ["a person throws punches."], ["a person throws punches."]],
                  [walk, punch, punch[:12]], gen._text_encoder())
    return mem


def test_retrieved_codes_are_the_nearest_captions_clips(gen, memory):
    rows = retrieved_codes(memory, gen._text_encoder(), "somebody punches", 1, 20, 20)
    assert [r[0] for r in rows] == ["punch_1"] * 3      # a 30-code clip gives three 20-code windows
    assert rows[0][1] > 0.7 and rows[0][2] == [int(x) for x in memory.clip_tokens[1][:20]]
    rows = retrieved_codes(memory, gen._text_encoder(), "somebody punches", 2, 4, 50)
    assert [r[0] for r in rows] == ["punch_1", "walk_1"]  # one clip per caption, then the next caption's
    assert retrieved_codes(None, gen._text_encoder(), "x", 2, 4, 50) == []


def test_a_library_clip_competes_beside_nearer_training_captions(gen, memory):
    """A user's library clip joins the candidates though training captions are nearer: the library
    clip nearest to the prompt when its caption is within ``LIBRARY_MARGIN`` of the nearest caption's
    similarity (and at least ``LIBRARY_FLOOR``), and the nearest library clip of an action the prompt
    names. A clip shorter than asked competes whole while it covers ``LIBRARY_SHORTEST`` of the
    length; a shorter one, one already retrieved, or one of another action far from the prompt is
    not offered."""
    from shapemove.core.generation.retrieved_candidates import LIBRARY_FLOOR, LIBRARY_MARGIN, library_codes

    reader = gen._text_encoder()
    codes = [int(x) for x in memory.clip_tokens[0]]     # any codes: the captions decide
    memory.add_clips(["library:mine", "library:short", "library:jab"],
                     [["a person punches with the left hand."], ["someone punches the air."], ["a boxer jabs."]],
                     [codes, codes[:4], codes], reader, actions=[[], [], ["punch"]])   # as if only the jab named one
    lib = {"library:mine", "library:short", "library:jab"}
    prompt = "somebody punches"
    found = retrieved_codes(memory, reader, prompt, 1, 10, 20)
    assert {r[0] for r in found} == {"punch_1"}       # the training punch is the nearest long caption
    near = max(s for _, s in memory.nearest(sentence_vectors(reader, [prompt]), 1)[0])
    c, sim = memory.nearest_of(sentence_vectors(reader, [prompt])[0], [3, 4, 5], 10)
    assert memory.clip_ids[c] == "library:mine" and near - LIBRARY_MARGIN <= sim < near and sim >= LIBRARY_FLOOR
    rows = library_codes(memory, reader, prompt, lib, found, 10, 20)
    assert [r[0] for r in rows] == ["library:mine", "library:jab"] and rows[0][2] == codes[:20]
    assert rows[0][1] == pytest.approx(sim) and rows[1][1] < near - LIBRARY_MARGIN   # the jab: by its action
    assert [r[0] for r in library_codes(memory, reader, prompt, lib, found, 10, 20, margin=near - sim - 0.01)] == \
        ["library:jab"]
    # the short clip (4 codes) is nearer than "mine" once 4 codes will do: asked 8, it competes whole
    assert memory.clip_ids[memory.nearest_of(sentence_vectors(reader, [prompt])[0], [3, 4, 5], 4)[0]] == "library:short"
    whole = library_codes(memory, reader, prompt, lib, retrieved_codes(memory, reader, prompt, 1, 8, 8), 8, 8)
    assert ("library:short", pytest.approx(memory.nearest_of(sentence_vectors(reader, [prompt])[0], [4], 4)[1]),
            codes[:4]) in [tuple(r) for r in whole]
    walk = "a person walks forward"                   # far from every library caption, no punch named
    assert library_codes(memory, reader, walk, lib, retrieved_codes(memory, reader, walk, 1, 10, 20), 10, 20) == []
    assert library_codes(memory, reader, prompt, lib, found + rows, 10, 20) == []    # already candidates
    assert library_codes(memory, reader, prompt, set(), found, 10, 20) == []


def test_generation_keeps_a_retrieved_clip_only_when_it_wins(gen, memory):
    from shapemove.core.generation.generate import Request

    old = gen.t5.memory
    gen.t5.memory = memory
    try:
        # retrieval first from similarity 0: only the retrieved windows compete
        m = gen.generate_batch([Request("a man throws punches", seconds=4, seed=0, retrieval_first=0.0)])[0]
        assert m.retrieved_clips == ["punch_1"]
        assert any(list(m.tokens) == w for w in windows(memory.clip_tokens[1], 20, 20))
        # no clips offered: the samples alone
        m = gen.generate_batch([Request("a man throws punches", seconds=4, seed=0, retrieved=0)])[0]
        assert m.retrieved_clips == []
        # retrieval off turns the candidates off too
        gen.set_retrieval(False)
        m = gen.generate_batch([Request("a man throws punches", seconds=4, seed=0, retrieval_first=0.0)])[0]
        assert m.retrieved_clips == []
    finally:
        gen.t5.memory = old
        gen.set_retrieval(True)
    with pytest.raises(ShapeMoveError, match="retrieved clips"):
        gen.generate_batch([Request("a man throws punches", retrieved=-1)])
    with pytest.raises(ShapeMoveError, match="retrieval-first"):
        gen.generate_batch([Request("a man throws punches", retrieval_first=1.5)])


def test_a_retrieved_clip_of_another_action_than_the_words_ask_does_not_compete(gen, memory):
    """"an old man sits down slowly" found an elderly walk by its caption and walked 9 m: a clip
    labelled with another action than the one asked is not offered, as a captured take of it is not
    (``captured_takes.action_credit``); with nothing asked, or the action asked, it is."""
    from shapemove.core.generation.generate import Request

    assert memory.main_action("walk_1") == "walk" and memory.main_action("punch_1") == "punch"
    assert memory.main_action("no such clip") is None
    old = gen.t5.memory
    gen.t5.memory = memory
    try:   # retrieval first from similarity 0: the retrieved windows alone, when any is offered
        m = gen.generate_batch([Request("a person sits down", seconds=4, seed=0, retrieval_first=0.0)])[0]
        assert m.retrieved_clips == []                      # neither a walk nor a punch sits: the samples
        m = gen.generate_batch([Request("a person walks forward", seconds=4, seed=0, retrieval_first=0.0)])[0]
        assert m.retrieved_clips == ["walk_1"]
    finally:
        gen.t5.memory = old
    real = gen.t5.memory
    assert real.main_action("dataset-2_walk_elderly_014") == "walk"   # the shipped memory's labels


def test_words_naming_no_action_keep_only_a_clip_whose_caption_says_them(gen):
    """"a woman does aerobics" walked 5.6 m on an active walk's codes: with no action named, a clip
    competes only from ``NAMELESS_FLOOR`` (a named action keeps any clip of it)."""
    from shapemove.core.generation.generate import Request
    from shapemove.core.generation.retrieved_candidates import NAMELESS_FLOOR
    from shapemove.core.models.motion_memory import MotionMemory

    walk = gen.tokens_for([Request("a person walks backwards", seconds=4, seed=0, candidates=1)])[0][0]
    guitar = gen.tokens_for([Request("a person raises both hands", seconds=4, seed=0, candidates=1)])[0][0]
    mem = MotionMemory.empty()
    mem.add_clips(["back_1", "guitar_1"], [["a person walks backwards."], ["a person plays the guitar."]],
                  [walk, guitar], gen._text_encoder())
    near = {p: retrieved_codes(mem, gen._text_encoder(), p, 1, 4, 50)[0] for p in
            ("a woman looks back", "somebody plays the guitar", "a woman walks backwards slowly")}
    assert near["a woman looks back"][0] == "back_1" and near["a woman looks back"][1] < NAMELESS_FLOOR
    assert near["somebody plays the guitar"][0] == "guitar_1" and near["somebody plays the guitar"][1] >= NAMELESS_FLOOR
    old = gen.t5.memory
    gen.t5.memory = mem
    try:   # retrieval first from similarity 0: the retrieved windows alone, when any is offered
        got = {p: gen.generate_batch([Request(p, seconds=4, seed=0, retrieval_first=0.0)])[0].retrieved_clips
               for p in near}
    finally:
        gen.t5.memory = old
    assert got == {"a woman looks back": [], "somebody plays the guitar": ["guitar_1"],
                   "a woman walks backwards slowly": ["back_1"]}, got


def test_a_judge_does_not_find_the_retrieved_take_itself():
    from shapemove.core.eval.action_classifier import ActionClassifier
    from shapemove.core.models.motion_memory import family, take_of

    assert take_of("clip_7_mirror_aug") == take_of("clip_7") == "clip_7"
    e = np.eye(8, dtype=np.float32)[[0, 0, 0, 1, 1, 1, 2, 2]] + 0.01
    labels = ["kick"] * 3 + ["walk"] * 3 + ["wave"] * 2
    sources = ["k", "k_mirror", "k_aug", "w1", "w2", "w3", "v1", "v2"]
    clf = ActionClassifier(e, labels, None, 3, {}, None, sources)
    q = np.eye(8, dtype=np.float32)[[0]] + 0.02
    assert clf.classify_embeddings(q) == ["kick"]
    # the query IS take "k": without its three copies, the kick is no longer its own neighbour
    assert clf.classify_embeddings(q, exclude=["k_mirror"]) != ["kick"]
    assert clf.classify_embeddings(q, exclude=[None]) == ["kick"]
    assert clf.classify_embeddings(q, exclude=[["w1", "k"]]) != ["kick"]   # a motion made of two retrieved clips
    assert family("clip_7_mirror", {"composed_from": ["a_aug", "b"]}) == {"clip_7", "a", "b"}


def test_a_users_library_becomes_retrieved_candidates(gen, tmp_path):
    """``add_library`` adds a user's captioned motions to the model's memory (the default ships the
    memory of its training clips): the user's motion is then a candidate that wins when only
    retrieved clips compete."""
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.scene.motion_file import save_motion

    lib = tmp_path / "library"
    lib.mkdir()
    text = "a person does jumping jacks on a purple trampoline"   # a caption no training clip has
    m = gen.generate_batch([Request(text, seconds=5, seed=0, by_parts=False)])[0]
    save_motion(lib / "jacks.npz", m)
    own = Generator(None)
    own.set_captured(False)
    before = len(own.t5.memory)
    assert before > 1000 and own.add_library(lib) == 1 and len(own.t5.memory) == before + 1
    out = own.generate_batch([Request("someone does jumping jacks on a purple trampoline", seconds=4, seed=0,
                                      retrieval_first=0.0)])[0]
    assert out.retrieved_clips and out.retrieved_clips[0].startswith("library:")
    assert out.tokens is not None and not out.notes      # its codes carry it: decoded as any candidate
    (tmp_path / "empty").mkdir()
    with pytest.raises(ShapeMoveError, match="no motion with a caption"):
        own.add_library(tmp_path / "empty")


def test_library_clip_reads_motion_files_as_takes_and_refuses_bad_ones(tmp_path):
    """``motion_search.library_clip``: a ShapeMove motion file (joints at its own fps) or a features
    file is a take (Motion22); a mocap or AMASS file is left for the mocap readers; bad arrays and
    pickles are refused by name, sizes bounded before anything is read."""
    from shapemove.core.search.motion_search import library_clip

    joints = np.random.default_rng(0).normal(size=(30, 24, 3)).astype(np.float32)
    np.savez(tmp_path / "m.npz", joints=joints, poses=np.zeros((30, 24, 3)), transl=np.zeros((30, 3)), fps=30.0)
    m = library_clip(tmp_path / "m.npz")
    assert m.fps == 30.0 and m.joints.shape == (30, 22, 3) and np.allclose(m.joints, joints[:, :22])
    np.savez(tmp_path / "amass.npz", poses=np.zeros((5, 66)), trans=np.zeros((5, 3)))
    assert library_clip(tmp_path / "amass.npz") == tmp_path / "amass.npz"
    assert library_clip(tmp_path / "walk.bvh") == tmp_path / "walk.bvh"
    np.savez(tmp_path / "f.npz", features=np.zeros((10, 12)))
    with pytest.raises(ShapeMoveError, match=r"features must be \(T, 263\)"):
        library_clip(tmp_path / "f.npz")
    np.savez(tmp_path / "p.npz", joints=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ShapeMoveError, match="pickled"):
        library_clip(tmp_path / "p.npz")


def test_a_library_kick_the_codec_flattens_is_played_as_captured(mocap_root, openbody, tmp_path):
    """A user's captured front kick in the library: its codes would bring the right ankle's 1.0 m
    rise down to under half (retargeted through the SA-VAE, tests/test_code_search.py), so it
    competes as a captured take (``captured_takes.py``): kept for its own caption, its busiest
    window is played from the file by its own rotations, feet planted, starting at the origin facing
    +Z like a decoded motion, and says where it came from; the worker's generate job does the same
    with "library" (the Generate panel's "Use Library motions")."""
    import shutil

    import torch

    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.library_takes import window_start
    from shapemove.core.generation.retarget import source_joints
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.core.worker import jobs_shapemove

    assert window_start([5, 6, 7, 8, 6, 7], [6, 7]) == 1 and window_start([5, 6], [6, 5]) is None
    assert window_start([1, 2], [1, 2, 3]) is None and window_start([1, 2], []) is None
    lib = tmp_path / "library"
    lib.mkdir()
    kick = mocap_root / "bandai" / "dataset-1" / "data" / "dataset-1_kick_normal_001.bvh"
    shutil.copy(kick, lib / "kick.bvh")
    caption = "a person performs a zorblax front kick"     # no training caption is nearer than its own
    (lib / "kick.txt").write_text(caption + "\n")
    src = source_joints(kick, openbody)[0][:, 8, 1]
    own = Generator(None)
    assert own.add_library(lib) == 1
    m = own.generate_batch([Request(caption, seconds=4, seed=0, retrieval_first=0.0)])[0]
    assert m.provenance == "captured: kick.bvh (your library)" and m.tokens is None and m.num_frames == 80
    assert not m.notes and not m.warnings
    lift = lambda y: float(y.max() - y.min())  # noqa: E731   (the right ankle's rise)
    assert lift(src) > 0.9 and lift(m.joints[:, 8, 1]) > 0.9 * lift(src)
    j = m.joints
    across = (j[0, 1] - j[0, 2]) + (j[0, 16] - j[0, 17])
    facing = np.cross(across, [0.0, 1.0, 0.0])
    assert np.abs(j[0, 0, [0, 2]]).max() < 0.01 and abs(np.degrees(np.arctan2(facing[0], facing[2]))) < 3
    with torch.no_grad():                                  # the mesh stands on the floor in every frame
        v = openbody(torch.as_tensor(m.betas)[None].expand(m.num_frames, -1), torch.as_tensor(m.poses),
                     torch.as_tensor(m.transl)).vertices
    assert np.abs(v[..., 1].min(1).values.numpy()).max() < 0.005
    r = jobs_shapemove.generate({"prompt": caption, "seconds": 4, "library": str(lib), "out": str(tmp_path / "g.npz")},
                                lambda *a: None, lambda: False)
    assert r["tokens"] == 0 and r["provenance"] == "captured: kick.bvh (your library)" and not r["warnings"]
    assert lift(load_motion(tmp_path / "g.npz").joints[:, 8, 1]) > 0.9 * lift(src)
    # a body-shape change plants the take again on the new body (the panel's re-decode job)
    short = [-1.5] + [0.0] * 9
    again = jobs_shapemove.redecode({"motion": str(tmp_path / "g.npz"), "betas": short, "out": str(tmp_path / "s.npz")},
                                    lambda *a: None, lambda: False)
    s = load_motion(again["path"])
    assert again["tokens"] == 0 and np.allclose(s.betas, short) and s.contacts_measured and s.num_frames == 80
    assert lift(s.joints[:, 8, 1]) > 0.8 * lift(src)       # still a kick, on a shorter body
    with pytest.raises(ShapeMoveError, match="library folder not found"):
        jobs_shapemove.generate({"prompt": caption, "library": str(tmp_path / "nowhere"), "out": str(tmp_path / "x.npz")},
                                lambda *a: None, lambda: False)
    # asked longer than the take (11.8 s): played whole, its last pose held for the rest, and said
    whole = own.generate_batch([Request(caption, seconds=16, seed=0, retrieval_first=0.0)])[0]
    assert whole.provenance == "captured: kick.bvh (your library)" and whole.num_frames == 320
    assert any("its last pose is held for the remaining 4.1 s" in n for n in whole.notes)
    assert lift(whole.joints[:, 8, 1]) > 0.9 * lift(src)


def test_a_library_kick_loops_and_stays_in_place_as_captured(mocap_root, openbody, tmp_path, monkeypatch):
    """Generate Animated with the Library (the worker's animate job, "library"): a loop of a kept
    library kick is cut from the captured take with the kick inside the cycle, and held in place it
    keeps its rise; both carry the note. Without the library the same job loops the model's codes, which
    flatten the kick."""
    import shutil

    from shapemove.core.generation.loop import seam_report
    from shapemove.core.generation.retarget import source_joints
    from shapemove.core.scene.motion_file import load_motion
    from shapemove.core.worker import jobs_animation

    lib = tmp_path / "library"
    lib.mkdir()
    kick = mocap_root / "bandai" / "dataset-1" / "data" / "dataset-1_kick_normal_001.bvh"
    shutil.copy(kick, lib / "kick.bvh")
    caption = "a person performs a zorblax front kick"
    (lib / "kick.txt").write_text(caption + "\n")
    lift = lambda y: float(y.max() - y.min())  # noqa: E731   (the right ankle's rise)
    src = lift(source_joints(kick, openbody)[0][:, 8, 1])
    job = lambda **p: jobs_animation.animate({"prompt": caption, "seed": 0, "out": str(tmp_path / "a.npz"), **p},  # noqa: E731
                                             lambda *a: None, lambda: False)
    r = job(loop=True, seconds=2.0, library=str(lib))
    m = load_motion(r["path"])
    assert r["tokens"] == 0 and len(r["notes"]) == 1 and "kick.bvh" in r["notes"][0] and "loop_advance" in r
    assert 34 <= m.num_frames <= 46 and lift(m.joints[:, 8, 1]) > 0.85 * src    # a 2 s cycle holding the kick
    assert seam_report(m)["jump_ratio"] < 3.0
    r = job(in_place=True, seconds=4.0, library=str(lib))
    m = load_motion(r["path"])
    assert r["tokens"] == 0 and m.provenance == "captured: kick.bvh (your library)" and m.num_frames == 80
    assert np.ptp(m.joints[:, 0, [0, 2]], axis=0).max() < 1e-4 and lift(m.joints[:, 8, 1]) > 0.85 * src
    r = job(loop=True, seconds=2.0)                     # the codes' loop: the kick flattened
    assert not r["notes"] and lift(load_motion(r["path"]).joints[:, 8, 1]) < 0.5 * src
    # a prompt no library clip competes for is sampled once, not first for the library and again
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.loop import generate_loop

    gen = Generator(None)
    gen.add_library(lib)
    calls = []
    tokens_for = gen.tokens_for
    monkeypatch.setattr(gen, "tokens_for", lambda *a, **k: calls.append(1) or tokens_for(*a, **k))
    assert not gen.offers_library(Request("a person walks forward", seconds=2.0))
    walk = generate_loop(gen, Request("a person walks forward", seconds=2.0, seed=0, by_parts=False))
    assert calls == [] and not walk.notes
    assert gen.offers_library(Request(caption, seconds=2.0))
    generate_loop(gen, Request(caption, seconds=2.0, seed=0, by_parts=False))
    assert calls == [1]


def test_a_library_kick_is_found_for_words_the_training_kicks_are_nearer_to(mocap_root, openbody, tmp_path,
                                                                           monkeypatch):
    """"a karate front kick" is nearer to the training set's kicks (0.73) than to the user's "a
    person does a high front kick with the right leg" (0.67), "a woman kicks" to "A person kicks."
    (0.90 against 0.56): the user's kick competes as a captured take all the same (the user's
    nearest clip by caption and their nearest of the action named, ``TakePool.nearest``), is kept
    and is played as captured. A walk or a punch is not given the kick. With captured takes off
    (``--no-library``) the user's clip competes by its codes (``library_codes``); without those,
    the codes' kick barely lifts the ankle."""
    import shutil

    from shapemove.core.generation import generate as generate_module
    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.generation.retarget import source_joints

    lib = tmp_path / "library"
    lib.mkdir()
    kick = mocap_root / "bandai" / "dataset-1" / "data" / "dataset-1_kick_normal_001.bvh"
    shutil.copy(kick, lib / "kick.bvh")
    (lib / "kick.txt").write_text("a person does a high front kick with the right leg\n")
    lift = lambda y: float(y.max() - y.min())  # noqa: E731   (the right ankle's rise)
    src = lift(source_joints(kick, openbody)[0][:, 8, 1])
    from shapemove.core.generation.model_bundle import resolve_model_dir
    from shapemove.core.model_files import write_manifest

    model = tmp_path / "model"     # the default model without its built-in library: the user's kick alone
    shutil.copytree(resolve_model_dir(None), model)
    (model / "library.npz").unlink(missing_ok=True)
    write_manifest(model)
    own = Generator(model)
    own.add_library(lib)
    run = lambda p: own.generate_batch([Request(p, seconds=4, seed=0)])[0]  # noqa: E731
    mine = "captured: kick.bvh (your library)"
    m = run("a karate front kick")
    assert m.provenance == mine and lift(m.joints[:, 8, 1]) > 0.9 * src
    m = run("a woman kicks")                         # nearest "A person kicks." (0.90): the user's kick by its action
    assert m.provenance == mine and lift(m.joints[:, 8, 1]) > 0.85 * src
    assert run("a person walks forward").provenance != mine
    assert run("a person punches").provenance != mine
    own.set_captured(False)
    m = run("a karate front kick")
    assert m.retrieved_clips == ["library:kick"] and len(m.notes) == 1 and lift(m.joints[:, 8, 1]) > 0.9 * src
    monkeypatch.setattr(generate_module, "library_codes", lambda *a, **k: [])
    m = run("a karate front kick")
    assert "library:kick" not in m.retrieved_clips and lift(m.joints[:, 8, 1]) < 0.3 * src


def test_a_model_folder_with_a_memory_retrieves_from_it(gen, tmp_path):
    """A memory written beside a T5 that does not read one (tools/build_motion_memory.py does this
    for a trained model) is loaded and retrieved from; one with codes the model lacks is refused."""
    import shutil

    from shapemove.core.generation.generate import Generator, Request
    from shapemove.core.model_files import write_manifest
    from shapemove.core.models.motion_memory import MotionMemory

    model = tmp_path / "model"
    shutil.copytree(gen.model_dir, model)
    codes = gen.tokens_for([Request("a person throws punches", seconds=5, seed=0, candidates=1)])[0][0]
    mem = MotionMemory.empty()
    mem.add_clips(["punch_9"], [["a person throws punches."]], [codes], gen._text_encoder())
    mem.save(model / "t5")
    write_manifest(model)
    own = Generator(model)
    own.set_captured(False)
    assert own.t5.memory_k == 0 and own.t5.memory.clip_ids == ["punch_9"]
    m = own.generate_batch([Request("someone punches", seconds=4, seed=0, retrieval_first=0.0)])[0]
    assert m.retrieved_clips == ["punch_9"]
    bad = MotionMemory.empty()
    bad.add_clips(["x"], [["a person waves."]], [[1000 * 1001, 1]], gen._text_encoder())  # past base + residual
    bad.save(model / "t5")
    write_manifest(model)
    with pytest.raises(ShapeMoveError, match="codes outside"):
        Generator(model)
