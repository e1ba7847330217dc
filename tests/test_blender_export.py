"""Exports read back through Blender's own importers with their default settings.

An OpenBody rig is built in real bpy (in this process) from a moving motion, exported as glTF,
FBX and BVH by ``shapemove_addon.export``, then imported with ``bpy.ops.import_scene.gltf``,
``import_scene.fbx`` and ``import_anim.bvh`` (no options). At every frame the imported bones
(and, for glTF/FBX, the skinned mesh) must sit where the original ones are: <= 1 mm. The glTF is
checked by the Khronos glTF validator (npm ``gltf-validator``, installed by ``make setup``).
"""
from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from shapemove.core.scene.motion_file import make_motion

bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
from bpy_readback import bone_heads_world, evaluated_vertices  # noqa: E402
pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 12
MM = 1e-3
VALIDATOR = ROOT / ".venv" / "node" / "node_modules" / "gltf-validator" / "package.json"


def _motion(body):
    rng = np.random.default_rng(3)
    t = np.arange(FRAMES)[:, None, None]
    poses = rng.normal(0, 0.5, (1, 24, 3)) * np.sin(0.25 * t + rng.uniform(0, 6, (1, 24, 3)))
    step = np.arange(FRAMES)
    transl = np.stack([0.02 * step, 0.03 * np.sin(0.4 * step), 0.05 * step], -1)
    return make_motion(body, poses, transl, rng.normal(0, 1, 10), fps=20, prompt="export test")


@pytest.fixture(scope="module")
def exported(tmp_path_factory, openbody):
    from shapemove.shapemove_addon import export
    from shapemove.shapemove_addon.scene_build import build_rig

    d = tmp_path_factory.mktemp("export")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    rig = build_rig(bpy.context, _motion(openbody), openbody, name="Rig")
    scene = bpy.context.scene
    names = [b.name for b in rig.armature.data.bones]
    ref = {}
    for f in range(1, FRAMES + 1):
        scene.frame_set(f)
        ref[f] = (bone_heads_world(rig.armature, names), evaluated_vertices(rig.body))
    basis = np.array([list(v.co) for v in rig.body.data.shape_keys.key_blocks["Basis"].data])
    files = {fmt: export.export_rig(bpy.context, rig.armature, d / "rig", fmt) for fmt in export.FORMATS}
    yield dict(rig=rig, names=names, ref=ref, basis=basis, files=files, dir=d)
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _reimport(exported, fmt):
    """Import with Blender's defaults -> (armature, body mesh or None, per-frame errors)."""
    from mathutils.kdtree import KDTree

    path = str(exported["files"][fmt])
    before = set(bpy.data.objects)
    {"GLTF": lambda: bpy.ops.import_scene.gltf(filepath=path), "FBX": lambda: bpy.ops.import_scene.fbx(filepath=path),
     "BVH": lambda: bpy.ops.import_anim.bvh(filepath=path)}[fmt]()
    new = [o for o in bpy.data.objects if o not in before]
    try:
        arm = next(o for o in new if o.type == "ARMATURE")
        body = next((o for o in new if o.type == "MESH" and len(o.data.vertices) == len(exported["basis"])), None)
        match = None
        if body is not None:  # imported vertex -> original vertex, by rest (Basis) position
            kd = KDTree(len(exported["basis"]))
            for i, v in enumerate(exported["basis"]):
                kd.insert(v, i)
            kd.balance()
            own = body.data.shape_keys.key_blocks[0].data if body.data.shape_keys else body.data.vertices
            found = [kd.find(body.matrix_world @ v.co) for v in own]
            assert max(f[2] for f in found) < 1e-5
            match = np.array([f[1] for f in found])
        scale = 0.01 if fmt == "BVH" else 1.0  # the BVH is in centimetres; Blender reads its numbers as metres
        action = arm.animation_data.action
        out = dict(frame_range=[int(round(x)) for x in action.frame_range], bones=sorted(b.name for b in arm.data.bones),
                   bone_err=[], mesh_err=[], upright=None, vertices=len(body.data.vertices) if body else 0)
        for f in range(1, FRAMES + 1):  # the same scene frame == the same time (20 fps, frame 1 = 0 s)
            bpy.context.scene.frame_set(f)
            heads, verts = exported["ref"][f]
            out["bone_err"].append(float(np.abs(bone_heads_world(arm, exported["names"]) * scale - heads).max()))
            if match is not None:
                out["mesh_err"].append(float(np.abs(evaluated_vertices(body) - verts[match]).max()))
        rest = {b.name: b.head_local for b in arm.data.bones}
        out["upright"] = float((arm.matrix_world @ rest["head"]).z - (arm.matrix_world @ rest["pelvis"]).z) * scale
        return out
    finally:
        for o in new:
            bpy.data.objects.remove(o)


def test_gltf_reimports_bones_and_mesh_within_a_millimetre(exported):
    r = _reimport(exported, "GLTF")
    assert r["bones"] == sorted(exported["names"]) and r["frame_range"] == [1, FRAMES]
    assert r["vertices"] == len(exported["basis"])
    assert max(r["bone_err"]) <= MM, r["bone_err"]
    assert max(r["mesh_err"]) <= MM, r["mesh_err"]


def _glb_json(path) -> dict:
    data = Path(path).read_bytes()
    magic, _, _ = struct.unpack_from("<4sII", data, 0)
    length, kind = struct.unpack_from("<I4s", data, 12)
    assert magic == b"glTF" and kind == b"JSON"
    return json.loads(data[20:20 + length])


def test_gltf_carries_every_skin_influence(exported, openbody):
    gltf = _glb_json(exported["files"]["GLTF"])
    prim = next(p for m in gltf["meshes"] for p in m["primitives"] if "JOINTS_0" in p["attributes"])
    sets = sorted(k for k in prim["attributes"] if k.startswith("JOINTS_"))
    most = int((np.asarray(openbody.skin_weights) > 0).sum(1).max())
    assert most > 4  # the body has vertices with more than 4 influences ...
    assert len(sets) * 4 >= most  # ... and the file has room for all of them (JOINTS_0, JOINTS_1, ...)
    assert len(gltf["animations"]) == 1
    times = gltf["accessors"][gltf["animations"][0]["samplers"][0]["input"]]
    # Blender's glTF convention (its importer puts time t at frame t * fps): frame f at f / fps
    assert times["min"][0] == pytest.approx(1 / 20, abs=1e-6) and times["max"][0] == pytest.approx(FRAMES / 20, abs=1e-6)


def test_gltf_passes_the_khronos_validator(exported):
    if not VALIDATOR.is_file() or shutil.which("node") is None:
        if os.environ.get("SHAPEMOVE_REQUIRE_DATA") == "1":
            pytest.fail("the glTF validator is not installed: run `make setup` (needs node and npm)")
        pytest.skip("the glTF validator is not installed (`make setup` installs it; needs node and npm)")
    proc = subprocess.run(["node", str(ROOT / "tests" / "gltf_validate.js"), str(exported["files"]["GLTF"])],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    errors = [m for m in report["issues"]["messages"] if m["severity"] == 0]
    assert report["issues"]["numErrors"] == 0, errors[:10]
    assert report["info"]["animationCount"] == 1 and report["info"]["hasSkins"] and report["info"]["hasMorphTargets"]


def test_fbx_reimports_bones_and_mesh_within_a_millimetre(exported):
    r = _reimport(exported, "FBX")
    assert r["bones"] == sorted(exported["names"]) and r["frame_range"] == [1, FRAMES]
    assert r["vertices"] == len(exported["basis"])
    assert max(r["bone_err"]) <= MM, r["bone_err"]
    assert max(r["mesh_err"]) <= MM, r["mesh_err"]


def test_fbx_is_in_metres_at_scale_one_from_time_zero(exported):
    from io_scene_fbx import parse_fbx  # Blender's own FBX reader (on sys.path once bpy is imported)

    root, _ = parse_fbx.parse(str(exported["files"]["FBX"]))

    def children(elem, name):
        return [c for c in elem.elems if c.id == name]

    gs = children(children(root, b"GlobalSettings")[0], b"Properties70")[0]
    settings = {p.props[0]: p.props[4:] for p in gs.elems}
    assert settings[b"UnitScaleFactor"] == [100.0]  # 1 file unit = 100 cm: game engines import metres at scale 1
    assert settings[b"UpAxis"] == [1] and settings[b"UpAxisSign"] == [1]  # Y up
    objects = children(root, b"Objects")[0]
    parent = {c.props[1]: c.props[2] for c in children(root, b"Connections")[0].elems if c.props[0] == b"OO"}
    roots = [m for m in children(objects, b"Model") if parent.get(m.props[0]) == 0]
    assert len(roots) == 2
    for m in roots:  # no 100x root nodes
        found = children(m, b"Properties70")
        props = {p.props[0]: p.props[4:] for p in found[0].elems} if found else {}
        assert np.allclose(props.get(b"Lcl Scaling", [1.0, 1.0, 1.0]), 1.0), m.props[1]
    first = min(int(children(c, b"KeyTime")[0].props[0][0]) for c in children(objects, b"AnimationCurve"))
    assert first == 0  # the first frame is time 0


def test_bvh_is_y_up_in_centimetres_and_reimports_within_a_millimetre(exported, openbody):
    text = Path(exported["files"]["BVH"]).read_text()
    assert text.startswith("HIERARCHY\nROOT pelvis\n{\n\tOFFSET ")
    root_offset = np.array(text.splitlines()[3].split()[1:4], dtype=float)
    rest_pelvis = exported["rig"].armature.data.bones["pelvis"].head_local
    assert root_offset[1] == pytest.approx(100 * rest_pelvis.z, abs=1e-3)  # Blender's Z (up) is the file's Y, in cm
    assert root_offset[1] > 50  # a pelvis 0.5-1.2 m above the feet, in centimetres
    assert "Frames: %d\nFrame Time: 0.05000000" % FRAMES in text
    r = _reimport(exported, "BVH")
    assert r["bones"] == sorted(exported["names"]) and r["frame_range"] == [1, FRAMES]
    assert r["upright"] > 0.3  # standing (head above pelvis in Blender's Z), not lying on its back
    assert max(r["bone_err"]) <= MM, r["bone_err"]


def test_bvh_reads_back_with_the_projects_own_reader(exported):
    from shapemove.core.io.bvh import load_bvh
    from shapemove.core.scene.axes import points_to_y_up

    mocap = load_bvh(exported["files"]["BVH"])
    arm, names = exported["rig"].armature, exported["names"]
    assert mocap.unit == "cm" and mocap.up_axis == "Y"  # what the file says it is
    joints = np.asarray(mocap.positions, dtype=np.float64)
    order = [list(mocap.names).index(n) for n in names]
    assert joints.shape[0] == FRAMES
    for f in (1, FRAMES // 2, FRAMES):
        heads = points_to_y_up(exported["ref"][f][0])
        assert np.abs(joints[f - 1][order] - heads).max() <= MM
