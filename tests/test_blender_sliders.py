"""Shape sliders on a real OpenBody rig in bpy (this process): no drift after many moves, the motion
kept, the feet kept on the floor (with and without motion tokens). Each update's time is measured by
`python -m shapemove bench sliders`, not here."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from shapemove.core.scene.axes import points_to_z_up
from shapemove.core.scene.motion_file import make_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from bpy_readback import bone_heads_world, evaluated_vertices  # noqa: E402
pytestmark = pytest.mark.blender

FRAMES = 24
MM = 1e-3


def _squat(body, betas, seed=0):
    """Knees and hips bending and straightening in place, grounded frame by frame: each frame's
    lowest mesh vertex is on the floor (y = 0) for ``betas``; both feet stay planted."""
    rng = np.random.default_rng(seed)
    t = np.arange(FRAMES)
    bend = 0.7 * (1 - np.cos(2 * np.pi * t / FRAMES))  # 0 .. 1.4 rad .. 0
    poses = np.repeat(rng.normal(0, 0.05, (1, 24, 3)), FRAMES, 0)
    poses[:, [1, 2], 0] = -bend[:, None]
    poses[:, [4, 5], 0] = 2 * bend[:, None]
    poses[:, [7, 8], 0] = -0.5 * bend[:, None]
    transl = np.zeros((FRAMES, 3))
    with torch.no_grad():
        out = body.forward(torch.as_tensor(betas, dtype=torch.float32)[None].expand(FRAMES, -1),
                           torch.as_tensor(poses, dtype=torch.float32), torch.as_tensor(transl, dtype=torch.float32))
    transl[:, 1] -= out.vertices[:, :, 1].min(1).values.numpy()
    return poses, transl


def _forward(body, betas, poses, transl):
    with torch.no_grad():
        out = body.forward(torch.as_tensor(betas, dtype=torch.float32)[None].expand(len(poses), -1),
                           torch.as_tensor(poses, dtype=torch.float32), torch.as_tensor(transl, dtype=torch.float32))
    return out.joints.numpy().astype(np.float64), out.vertices.numpy().astype(np.float64)


def _height_beta(body) -> int:
    """The beta that changes the rest skeleton's head-to-ankle height most."""
    jd = np.asarray(body.joint_shapedirs)
    return int(np.argmax(np.abs(jd[15, 1] - jd[7, 1])))


@pytest.fixture()
def scene(tmp_path, openbody):
    from shapemove.shapemove_addon import redecode
    from shapemove.shapemove_addon.scene_build import build_rig

    bpy.ops.wm.read_factory_settings(use_empty=True)
    betas = np.random.default_rng(7).normal(0, 0.7, 10)
    poses, transl = _squat(openbody, betas)

    def build(tokens: bool):
        motion = make_motion(openbody, poses, transl, betas, fps=20, prompt="squats while walking",
                             **({"tokens": np.arange(5, dtype=np.int16)} if tokens else {}))
        rig = build_rig(bpy.context, motion, openbody, name="Rig")
        if tokens:  # what the operator stores for a generated motion
            rig.armature[redecode.MOTION_FILE_KEY] = str(tmp_path / "motion.npz")
            rig.armature[redecode.HAS_TOKENS_KEY] = True
        bpy.context.view_layer.objects.active = rig.armature
        return rig, motion

    yield build, betas, poses, transl
    redecode.unregister()
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _state(rig, frames):
    names = rig.armature["shapemove_joint_names"].split("\n")
    out = []
    for f in frames:
        bpy.context.scene.frame_set(f)
        out.append((bone_heads_world(rig.armature, names), evaluated_vertices(rig.body)))
    return out


def test_two_hundred_slider_moves_do_not_drift(scene):
    from shapemove.shapemove_addon.shape_sync import set_betas

    build, betas, _, _ = scene
    rig, _ = build(tokens=False)
    frames = [1, FRAMES // 3, FRAMES // 2, FRAMES]
    built = _state(rig, frames)
    set_betas(rig.armature, betas)  # the first update grounds the keyed motion on the mesh soles ...
    before = _state(rig, frames)
    # ... which this motion already was (it was made standing on its lowest vertex)
    assert max(np.abs(a[0] - b[0]).max() for a, b in zip(built, before)) < MM
    rng = np.random.default_rng(11)
    moved = betas.copy()
    for k in range(200):  # one slider at a time, as a user drags them
        moved[k % 10] = betas[k % 10] + rng.uniform(-2, 2)
        set_betas(rig.armature, moved)
    mid = _state(rig, frames[:1])
    assert np.abs(mid[0][1] - before[0][1]).max() > 0.01  # the body did change shape meanwhile
    set_betas(rig.armature, betas)
    after = _state(rig, frames)
    bone_drift = max(np.abs(a[0] - b[0]).max() for a, b in zip(after, before))
    mesh_drift = max(np.abs(a[1] - b[1]).max() for a, b in zip(after, before))
    assert bone_drift <= 0.05 * MM and mesh_drift <= 0.05 * MM, (bone_drift, mesh_drift)


@pytest.mark.parametrize("tokens", [False, True], ids=["no-tokens", "tokens"])
def test_shape_change_keeps_the_motion_and_the_feet_on_the_floor(scene, openbody, tokens):
    from shapemove.shapemove_addon import redecode
    from shapemove.shapemove_addon.shape_sync import set_betas

    from shapemove.core.motion.contacts import detect_contacts

    build, betas, poses, transl = scene
    rig, motion = build(tokens=tokens)
    assert detect_contacts(motion.joints).any(1).all()  # a foot is planted in every frame
    new = betas.copy()
    new[_height_beta(openbody)] += 2.5
    set_betas(rig.armature, new)
    joints, verts = _forward(openbody, new, poses, transl)  # the same keys on the new body, not grounded
    names = rig.armature["shapemove_joint_names"].split("\n")
    rel_err, floor, ungrounded = [], [], []
    for k in range(FRAMES):
        bpy.context.scene.frame_set(1 + k)
        heads = bone_heads_world(rig.armature, names[:22])
        want = points_to_z_up(joints[k, :22])
        rel_err.append(np.abs((heads - heads[0]) - (want - want[0])).max())  # the pose is the motion's
        floor.append(evaluated_vertices(rig.body)[:, 2].min())  # the body's lowest point: the soles
        ungrounded.append(verts[k, :, 1].min())
    assert max(rel_err) <= MM
    assert np.abs(floor).max() <= MM, np.round(floor, 4)
    assert np.abs(ungrounded).max() > 0.01  # without the grounding the soles would leave the floor
    assert (rig.armature.name in redecode.pending()) == tokens  # a generated motion is also re-decoded
