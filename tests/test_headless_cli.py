"""The headless commands end to end with tiny trained models: `demo` and `render` write a .blend,
a preview strip and the motion; a bad prompt in a batch is reported and skipped."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from tiny_models import tiny_bundle  # noqa: F401  (session fixture)

pytestmark = [pytest.mark.slow, pytest.mark.blender]


def _run(args, cwd):
    env = dict(os.environ, OMP_NUM_THREADS="1")
    return subprocess.run([sys.executable, "-m", "shapemove", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600)


def _png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def test_demo_writes_blend_preview_and_motion(tiny_bundle, tmp_path):
    model, _ = tiny_bundle
    r = _run(["demo", "--model", str(model), "--out", str(tmp_path / "demo"), "--seconds", "2", "--frames", "3"],
             tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    out = tmp_path / "demo"
    assert (out / "shapemove.blend").stat().st_size > 100_000
    w, h = _png_size(out / "preview.png")
    assert (w, h) == (3 * 320, 320)  # a strip of three 320x320 frames
    with np.load(out / "motion.npz") as z:
        assert z["poses"].shape == (40, 24, 3) and z["betas"].shape == (10,)
    for word in ("prompt:", "body:", "height", "scene:", "preview:"):
        assert word in r.stdout
    source = [ln for ln in r.stdout.splitlines() if ln.startswith("source:")]   # where the motion came from
    assert len(source) == 1 and ("captured: " in source[0] or "generated" in source[0]), r.stdout
    assert not list(out.glob("*.tmp*"))


def test_render_batch_skips_a_bad_prompt(tiny_bundle, tmp_path):
    model, _ = tiny_bundle
    prompts = tmp_path / "prompts.jsonl"
    prompts.write_text("\n".join(json.dumps(p) for p in [
        {"prompt": "a person walks forward", "seconds": 2},
        {"prompt": "12345 !!"},
        {"prompt": "someone waves with the left hand", "shape_text": "a short, slim woman", "seconds": 2.4},
    ]) + "\n")
    r = _run(["render", "--prompts", str(prompts), "--out", str(tmp_path / "r"), "--model", str(model),
              "--frames", "2", "--resolution", "96", "96"], tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "rendered 2 of 3 prompts" in r.stdout
    assert "no words" in r.stdout + r.stderr
    blends = sorted((tmp_path / "r").glob("*.blend"))
    assert [b.name[:3] for b in blends] == ["000", "002"]
    for b in blends:
        assert _png_size(b.with_suffix(".png")) == (2 * 96, 96)
    with np.load(blends[1].with_suffix(".npz")) as z:
        assert z["poses"].shape[0] == 48  # 2.4 s at 20 fps


def test_render_rejects_a_bad_prompts_file(tmp_path):
    bad = tmp_path / "p.jsonl"
    bad.write_text('{"prompt": "a person walks"}\nnot json\n')
    r = _run(["render", "--prompts", str(bad), "--out", str(tmp_path / "r")], tmp_path)
    assert r.returncode == 2 and "p.jsonl:2: not valid JSON" in r.stderr


def test_demo_names_the_body_by_its_gender_slider():
    """The demo's body line says "man" / "woman" from the gender slider read back from the betas."""
    import numpy as np

    from shapemove.cli.demo import _sex
    from shapemove.core.body.load import load_body_model
    from shapemove.core.body.shape_from_measurements import betas_for_shape_text

    body = load_body_model(None)
    assert _sex(body, betas_for_shape_text(body, "a tall, heavy-set man")) == "male"
    assert _sex(body, betas_for_shape_text(body, "a tall, heavy-set woman")) == "female"
    assert _sex(body, np.zeros(10, np.float32)) is None          # the average adult: neither


def test_render_with_a_library_plays_a_captured_kick(mocap_root, tmp_path):
    """`render --library DIR`: a pipeline's own captioned clips compete with the default model's
    samples; the captured kick the codec would flatten is played as captured and says so."""
    import shutil

    lib = tmp_path / "library"
    lib.mkdir()
    shutil.copy(mocap_root / "bandai" / "dataset-1" / "data" / "dataset-1_kick_normal_001.bvh", lib / "kick.bvh")
    (lib / "kick.txt").write_text("a person does a high front kick with the right leg\n")
    prompts = tmp_path / "prompts.jsonl"
    prompts.write_text(json.dumps({"prompt": "someone kicks high in front of them", "seconds": 4}) + "\n")
    r = _run(["render", "--prompts", str(prompts), "--out", str(tmp_path / "r"), "--library", str(lib),
              "--frames", "2", "--resolution", "96", "96"], tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    assert "1 motions added" in r.stdout and "rendered 1 of 1 prompts" in r.stdout
    assert "captured" in r.stdout + r.stderr        # a captured kick (the user's or the built-in library's)
    with np.load(tmp_path / "r" / "000_someone_kicks_high_in_front_of_them.npz") as z:
        joints = z["joints"]
        assert "tokens" not in z.files and joints.shape[0] == 80
    lift = max(float(joints[:, a, 1].max() - joints[:, a, 1].min()) for a in (7, 8))
    assert lift > 0.6      # an ankle's kick (the user's right kick or a built-in library's)


def test_demo_takes_the_body_from_the_prompt_when_it_says_who():
    """`demo --prompt "a short, stocky woman picks up a box"` makes her, not the demo's default man;
    a prompt without person words gets the default; a shape text given wins."""
    from shapemove.cli.demo import DEFAULT_SHAPE, demo_shape
    from shapemove.core.body.load import load_body_model

    body = load_body_model(None)
    assert demo_shape(body, "a short, stocky woman picks up a box", None) is None
    assert demo_shape(body, "an old man sits down slowly", "") is None
    assert demo_shape(body, "a person jogs forward and waves", None) == DEFAULT_SHAPE
    assert demo_shape(body, "someone kicks", "  ") == DEFAULT_SHAPE
    assert demo_shape(body, "a short woman waves", "a tall man") == "a tall man"
