"""Runs inside a fresh ``python`` with the bpy module (started by test_blender_addon.py):
installs the extension zip into a temporary user folder, builds rigs through the operator and
measures everything the tests assert. Usage: python blender_checks.py CONFIG.json -> RESULTS.json.

BLENDER_USER_RESOURCES must point at a temporary folder before bpy is imported, which is why
this runs in its own process.
"""
from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

CONFIG = json.loads(open(sys.argv[1]).read())
os.environ["BLENDER_USER_RESOURCES"] = CONFIG["user_resources"]

import bpy  # noqa: E402

RESULTS: dict = {"timings": {}}
ADDON = "bl_ext.user_default.shapemove"


def timed(name):
    def deco(fn):
        t0 = time.perf_counter()
        try:
            fn()
        except Exception as exc:  # record, keep measuring the rest
            import traceback

            RESULTS.setdefault("errors", {})[name] = f"{exc}\n{traceback.format_exc()}"
        RESULTS["timings"][name] = time.perf_counter() - t0
        return fn
    return deco


def ext(name):
    """A module of the installed extension (bl_ext.user_default.shapemove.<name>)."""
    import importlib

    return importlib.import_module(f"{ADDON}.{name}")


def datablock_counts():
    return {k: len(getattr(bpy.data, k)) for k in ("objects", "meshes", "armatures", "actions", "shape_keys", "collections")}


def bone_heads_world(arm, names):
    return np.array([list(arm.matrix_world @ arm.pose.bones[n].head) for n in names])


def evaluated_vertices(obj):
    ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    co = np.empty(len(ev.data.vertices) * 3, dtype=np.float32)
    ev.data.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]


bpy.ops.wm.read_factory_settings(use_empty=True)


@timed("install")
def _install():
    r = bpy.ops.extensions.package_install_files(filepath=CONFIG["zip"], repo="user_default", enable_on_install=True)
    RESULTS["install"] = {"result": sorted(r), "enabled": ADDON in bpy.context.preferences.addons,
                          "operator": hasattr(bpy.ops.shapemove, "build_from_motion"),
                          "panel": hasattr(bpy.types, "SHAPEMOVE_PT_shape"),
                          "torch_imported": "torch" in sys.modules}  # registering must not need torch


@timed("user_dir")
def _user_dir():
    # the installed extension keeps its files under bpy.utils.extension_path_user (4.2+)
    path = str(ext("shapemove_addon.paths").user_dir())
    RESULTS["user_dir"] = {"path": path, "expected": bpy.utils.extension_path_user(ADDON),
                           "in_user_resources": path.startswith(CONFIG["user_resources"] + os.sep)}


import torch  # noqa: E402  (after the install check above)


def check_rig(label, motion_path, lbs=True, model_file=""):
    motion = ext("core.scene.motion_file").load_motion(motion_path)
    body = ext("core.scene.bodies").load_body(motion.body_model, model_file or None)
    axes = ext("core.scene.axes")
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    res: dict = {}
    RESULTS[label] = res

    bystander = bpy.data.objects.new("Bystander", None)
    bpy.context.scene.collection.objects.link(bystander)
    bystander.location = (1.0, 2.0, 3.0)
    before = set(bpy.data.objects)
    r = bpy.ops.shapemove.build_from_motion(filepath=motion_path, body_model_file=model_file)
    new = set(bpy.data.objects) - before
    res["result"] = sorted(r)
    res["new_objects"] = sorted((o.name, o.type) for o in new)
    res["bystander_unchanged"] = tuple(bystander.location) == (1.0, 2.0, 3.0) and bystander.parent is None
    arm = next(o for o in new if o.type == "ARMATURE")
    mesh_obj = next(o for o in new if o.type == "MESH")
    keys = mesh_obj.data.shape_keys.key_blocks
    res.update(
        vertices=len(mesh_obj.data.vertices), body_vertices=body.num_vertices,
        shape_keys=[k.name for k in keys], slider_ranges=[(k.slider_min, k.slider_max) for k in keys[1:]],
        key_values=[k.value for k in keys[1:]], betas=motion.betas.tolist(),
        bones=[b.name for b in arm.data.bones], expected_bones=names,
        bone_parents={b.name: (b.parent.name if b.parent else None) for b in arm.data.bones},
        vertex_groups=[g.name for g in mesh_obj.vertex_groups],
        modifiers=[(m.type, m.object.name if m.object else None) for m in mesh_obj.modifiers],
        mesh_parent=mesh_obj.parent.name if mesh_obj.parent else None, armature=arm.name,
        transforms_identity=bool(np.allclose(np.array(arm.matrix_world), np.eye(4)) and np.allclose(np.array(mesh_obj.matrix_world), np.eye(4))),
        frame_range=[bpy.context.scene.frame_start, bpy.context.scene.frame_end],
        fps=bpy.context.scene.render.fps / bpy.context.scene.render.fps_base, motion_fps=motion.fps,
        frames=motion.num_frames,
    )
    fcurves = ext("shapemove_addon.keyframes").action_fcurves(arm.animation_data.action, arm)
    res["fcurves"] = len(fcurves)
    res["keys_per_fcurve"] = sorted({len(fc.keyframe_points) for fc in fcurves})
    res["keyed_frames"] = sorted({int(round(k.co[0])) for fc in fcurves for k in fc.keyframe_points})
    # every curve sits in the group of its bone (the Dope Sheet / Graph Editor channel list)
    res["misgrouped_fcurves"] = [f"{fc.data_path}[{fc.array_index}]" for fc in fcurves
                                 if fc.group is None or fc.data_path.split('"')[1] != fc.group.name]
    res["blender_version"] = list(bpy.app.version)

    # FK: evaluated bone heads == the motion's joints (Z-up)
    joints_z = axes.points_to_z_up(motion.joints)
    T = motion.num_frames
    errs, lbs_errs = [], []
    for k in sorted({0, T // 3, T // 2, T - 1}):
        bpy.context.scene.frame_set(1 + k)
        errs.append(float(np.abs(bone_heads_world(arm, names[:22]) - joints_z[k]).max()))
        if lbs:
            out = body.forward(torch.as_tensor(motion.betas)[None], torch.as_tensor(motion.poses[k:k + 1]),
                               torch.as_tensor(motion.transl[k:k + 1]))
            lbs_errs.append(float(np.abs(evaluated_vertices(mesh_obj) - axes.points_to_z_up(out.vertices[0].numpy())).max()))
    res["fk_max_error_m"] = max(errs)
    res["lbs_max_error_m"] = max(lbs_errs) if lbs_errs else None
    layout = ext("core.scene.rig_data").rig_data(body, motion.betas).bones
    rest = np.array([np.array(arm.data.bones[n].matrix_local) for n in names])
    res["rest_matrix_error"] = float(np.abs(rest[:, :3, :3] - layout.matrices).max())
    res["rest_head_error_m"] = float(np.abs(rest[:, :3, 3] - layout.heads).max())
    return motion, body, arm, mesh_obj


@timed("capsule")
def _capsule():
    motion, body, arm, mesh_obj = check_rig("capsule", CONFIG["motion"], model_file=CONFIG["capsule_model"])
    res = RESULTS["capsule"]
    names = list(ext("core.body.skeleton").JOINT_NAMES)
    axes = ext("core.scene.axes")
    sync = ext("shapemove_addon.shape_sync")
    # the "height" beta: largest effect on head-to-ankle height of the rest skeleton
    jd = body.joint_shapedirs.numpy()  # (24,3,10) Y-up
    head, ankle = names.index("head"), names.index("left_ankle")
    gain = jd[head, 1] - jd[ankle, 1]
    i = int(np.argmax(np.abs(gain)))
    step = 2.0 * np.sign(gain[i])

    def height():
        b = arm.data.bones
        return b["head"].head_local.z - b["left_ankle"].head_local.z

    h0 = height()
    bpy.context.view_layer.objects.active = arm
    arm.shapemove.betas[i] = float(motion.betas[i] + step)  # the panel slider path
    new_betas = motion.betas.astype(np.float64).copy()
    new_betas[i] += step
    res["height_beta"] = i
    res["height_before"], res["height_after"] = h0, height()
    res["height_expected_gain"] = float(abs(gain[i]) * 2.0)
    res["key_value_after"] = mesh_obj.data.shape_keys.key_blocks[f"beta_{i}"].value
    res["slider_value_after"] = arm.shapemove.betas[i]
    rest_new = axes.points_to_z_up(body.rest_joints(torch.as_tensor(new_betas, dtype=torch.float32)[None])[0].numpy())
    res["rest_heads_error_after_m"] = float(np.abs(np.array([list(arm.data.bones[n].head_local) for n in names]) - rest_new).max())
    k = motion.num_frames // 2
    bpy.context.scene.frame_set(1 + k)
    out = body.forward(torch.as_tensor(new_betas, dtype=torch.float32)[None], torch.as_tensor(motion.poses[k:k + 1]),
                       torch.as_tensor(motion.transl[k:k + 1]))
    res["fk_error_after_beta_m"] = float(np.abs(bone_heads_world(arm, names[:22]) - axes.points_to_z_up(out.joints[0, :22].numpy())).max())
    res["lbs_error_after_beta_m"] = float(np.abs(evaluated_vertices(mesh_obj) - axes.points_to_z_up(out.vertices[0].numpy())).max())

    # shape key edited directly (Shape Keys list): the depsgraph handler notices and schedules a fix
    j = (i + 1) % 10
    h1 = height()
    mesh_obj.data.shape_keys.key_blocks[f"beta_{j}"].value = float(mesh_obj.data.shape_keys.key_blocks[f"beta_{j}"].value + 1.0)
    bpy.context.view_layer.update()
    res["handler_stale"] = [o.name for o in sync.stale_rigs(bpy.context.scene)]
    res["handler_scheduled"] = bpy.app.timers.is_registered(sync._run_pending)
    sync._run_pending()  # the timer's work (timers do not run without Blender's event loop)
    res["handler_stale_after"] = [o.name for o in sync.stale_rigs(bpy.context.scene)]
    new_betas[j] += 1.0
    rest_new = axes.points_to_z_up(body.rest_joints(torch.as_tensor(new_betas, dtype=torch.float32)[None])[0].numpy())
    res["handler_rest_error_m"] = float(np.abs(np.array([list(arm.data.bones[n].head_local) for n in names]) - rest_new).max())
    res["handler_height_change"] = height() - h1


@timed("failure")
def _failure():
    res = RESULTS.setdefault("failure", {})
    # 1. bad input through the operator: a report, nothing created
    before = datablock_counts()
    try:
        r = bpy.ops.shapemove.build_from_motion(filepath=CONFIG["bad_motion"])
        res["operator_result"] = sorted(r)
    except RuntimeError as exc:  # bpy.ops raises on an ERROR report
        res["operator_error"] = str(exc)
    res["operator_counts_equal"] = before == datablock_counts()
    # 2. a failure half-way (the target collection is not in the view layer, so the bones cannot be
    #    edited): everything created so far is removed again
    motion = ext("core.scene.motion_file").load_motion(CONFIG["motion"])
    body = ext("core.scene.bodies").load_body(motion.body_model, CONFIG["capsule_model"])
    loose = bpy.data.collections.new("NotInScene")
    before = datablock_counts()
    try:
        ext("shapemove_addon.scene_build").build_rig(bpy.context, motion, body, name="Broken", collection=loose)
        res["midway_raised"] = None
    except Exception as exc:
        res["midway_raised"] = f"{type(exc).__name__}: {exc}"
    res["midway_counts_before"], res["midway_counts_after"] = before, datablock_counts()
    res["mode_after"] = bpy.context.mode
    bpy.data.collections.remove(loose)


@timed("render")
def _render():
    render = ext("shapemove_addon.preview_render")
    sync = ext("shapemove_addon.shape_sync")
    rig = bpy.data.objects[RESULTS["capsule"]["armature"]]
    scene = bpy.context.scene
    # keep only the rig under test visible
    for o in scene.objects:
        if o not in (rig, sync.body_of(rig)):
            o.hide_render = True
    render.add_preview_stage(bpy.context, rig, resolution=(96, 72))
    frames = [scene.frame_start, scene.frame_end]
    masks, res = [], {}
    from PIL import Image

    for f in frames:
        path = os.path.join(CONFIG["render_dir"], f"frame_{f}.png")
        render.render_frame(scene, f, path)
        px = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255
        body = (px[..., 0] - px[..., 2] > 0.2)  # the body is drawn in a warm flat colour
        masks.append(body)
        res[f"std_{f}"] = float(px.std())
    res["body_fraction"] = [float(m.mean()) for m in masks]
    cents = [np.argwhere(m).mean(0).tolist() if m.any() else None for m in masks]
    res["centroids"] = cents
    res["changed_body_pixels"] = float((masks[0] ^ masks[1]).mean())
    RESULTS["render"] = res


if CONFIG.get("openbody_motion"):
    @timed("openbody")
    def _openbody():
        check_rig("openbody", CONFIG["openbody_motion"], lbs=True)


if CONFIG.get("cli_blend"):
    @timed("cli")
    def _cli():
        from shapemove.cli import main

        out, png = CONFIG["cli_blend"], os.path.join(CONFIG["render_dir"], "cli.png")
        code = main(["blend", "--motion", CONFIG["motion"], "--body-model-file", CONFIG["capsule_model"], "--out", out, "--render", png, "--frame", "5",
                     "--resolution", "64", "48"])
        res = {"exit": code, "png": os.path.isfile(png), "blend": os.path.isfile(out)}
        bpy.ops.wm.open_mainfile(filepath=out)
        scene = bpy.context.scene
        arm = bpy.data.objects.get("ShapeMove")
        res.update(objects=sorted(o.type for o in scene.objects), frame_range=[scene.frame_start, scene.frame_end],
                   camera=scene.camera is not None, action=bool(arm and arm.animation_data and arm.animation_data.action))
        from PIL import Image

        res["png_std"] = float(np.asarray(Image.open(png).convert("RGB"), dtype=np.float64).std() / 255)
        RESULTS["cli"] = res


if CONFIG.get("cli_blend"):
    @timed("video")
    def _video():
        # render_video on the saved scene; the MP4 read back as a movie clip has every frame
        headless = ext("shapemove_addon.headless")
        mp4 = os.path.join(CONFIG["render_dir"], "cli.mp4")
        headless.render_video(CONFIG["cli_blend"], mp4)
        clip = bpy.data.movieclips.load(mp4)
        RESULTS["video"] = {"frames": clip.frame_duration, "size": list(clip.size),
                            "no_tmp": not any(".tmp" in f for f in os.listdir(CONFIG["render_dir"]))}


with open(CONFIG["results"], "w") as f:
    json.dump(RESULTS, f, indent=1, default=float)
