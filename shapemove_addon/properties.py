"""Properties ShapeMove adds to Blender data: ``Object.shapemove`` (per rig) and
``Scene.shapemove`` (the panels' inputs and results).

``betas`` is a view, not a copy: reading it returns the rig's shape-key values and writing it sets
the keys and moves the bones (``shape_sync.set_betas``), so the sliders and the Shape Keys list can
never disagree. The semantic sliders (height, weight, ...) are views too (``semantic_shape``).
"""
from __future__ import annotations

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from ..core.constants import NUM_BETAS
from ..core.plan.vocabulary import MANNER_SAID
from . import semantic_shape, shape_sync
from .rig_state import current_betas, rig_of


def _get_betas(self):
    rig = rig_of(self.id_data)
    return [float(b) for b in current_betas(rig)] if rig else [0.0] * NUM_BETAS


def _set_betas(self, values):
    rig = rig_of(self.id_data)
    if rig is None:
        return
    try:
        shape_sync.set_betas(rig, values, bpy.context)
    except Exception as exc:  # a setter cannot report; keep the UI alive
        print(f"ShapeMove: could not apply the shape: {exc}")


def _phenotype_property(name: str):
    label, lo, hi, description = semantic_shape.PHENOTYPES[name]

    def get(self):
        rig = rig_of(self.id_data)
        return float(semantic_shape.phenotype_values(rig).get(name, (lo + hi) / 2)) if rig else (lo + hi) / 2

    def set_(self, value):
        rig = rig_of(self.id_data)
        if rig is None:
            return
        try:
            semantic_shape.set_phenotype(rig, name, value, bpy.context)
        except Exception as exc:  # a setter cannot report; keep the UI alive
            print(f"ShapeMove: could not apply the {label.lower()} slider: {exc}")

    span = hi - lo
    return FloatProperty(name=label, description=description, get=get, set=set_, soft_min=lo, soft_max=hi,
                         min=lo - span, max=hi + span, precision=1 if name == "age" else 3)


_MEASURE = dict(min=0.0, precision=1, subtype="NONE", description="Measured on the rest-pose body (cm)")


class ShapeMoveObjectProperties(bpy.types.PropertyGroup):
    betas: FloatVectorProperty(
        name="Betas", description="Body shape (the body's shape keys beta_0..beta_9); bones follow",
        size=NUM_BETAS, min=-5.0, max=5.0, soft_min=-5.0, soft_max=5.0, precision=3,
        get=_get_betas, set=_set_betas,
    )
    height: _phenotype_property("height")
    weight: _phenotype_property("weight")
    age: _phenotype_property("age")
    muscle: _phenotype_property("muscle")
    gender: _phenotype_property("gender")
    proportions: _phenotype_property("proportions")
    # filled by the "measure" job (and by generation); 0 = not measured yet
    height_cm: FloatProperty(name="Height (cm)", **_MEASURE)
    chest_cm: FloatProperty(name="Chest (cm)", **_MEASURE)
    waist_cm: FloatProperty(name="Waist (cm)", **_MEASURE)
    hip_cm: FloatProperty(name="Hip (cm)", **_MEASURE)
    mass_kg: FloatProperty(name="Mass (kg)", min=0.0, precision=1,
                           description="Rest-pose mesh volume x 985 kg/m^3, a whole-body density (kg)")
    bmi: FloatProperty(name="BMI", min=0.0, precision=1, description="Body-mass index: mass / height^2 (kg/m^2)")


class ShapeMoveLibraryItem(bpy.types.PropertyGroup):
    # ``name`` (inherited) holds the clip id
    score: FloatProperty(name="Score", description="Cosine similarity to the query")
    path: StringProperty(name="Path", subtype="FILE_PATH")
    caption: StringProperty(name="Caption")


_SIDES = [("NONE", "No side", "No side named"), ("left hand", "Left hand", ""), ("right hand", "Right hand", ""),
          ("left foot", "Left foot", ""), ("right foot", "Right foot", "")]
_COURSES = [("NONE", "No course", "Straight, as the words go"), ("walk in a circle", "Circle", ""),
            ("walk in a figure eight", "Figure eight", ""), ("back and forth", "Back and forth", ""),
            ("zigzag", "Zigzag", ""), ("square", "Square", ""), ("diagonal", "Diagonal", ""),
            ("aside", "To the side", "")]
_MANNERS = [("NONE", "No manner", "As the captures do it plainly")] + [
    (m, m.replace("_", " ").capitalize(), said) for m, said in MANNER_SAID.items()]


class ShapeMovePlanSegment(bpy.types.PropertyGroup):
    """One segment of the plan shown under the prompt (``plan_ui.py``; ``core/plan/panel_fields.py``)."""
    text: StringProperty(name="Text", description="What the model reads for this segment")
    action: StringProperty(name="Action", description="The action asked (walk, run, sit, wave, kick, jump, ...)")
    side: EnumProperty(name="Side", items=_SIDES, default="NONE", description="The side that moves most")
    course: EnumProperty(name="Course", items=_COURSES, default="NONE", description="The course the gait walks")
    course_way: EnumProperty(name="Way", items=[("left", "Left", "Counter-clockwise"), ("right", "Right", "Clockwise")],
                             default="left")
    distance: FloatProperty(name="Distance", default=0.0, min=0.0, max=100.0, precision=1, subtype="DISTANCE",
                            description="Metres the gait goes, then stands (0: no distance)")
    count: IntProperty(name="Count", default=0, min=0, max=12, description="Jumps, hops or squats (0: no count)")
    manner: EnumProperty(name="Manner", items=_MANNERS, default="NONE",
                         description="How it is done: the captured takes done so compete")
    seconds: FloatProperty(name="Seconds", default=0.0, min=0.0, max=60.0, precision=1,
                           description="This segment's length (0: its share of the motion's length)")


def _is_rig(self, obj):
    return rig_of(obj) is obj


class ShapeMoveSceneSettings(bpy.types.PropertyGroup):
    # generate
    prompt: StringProperty(name="Prompt", default="a person walks forward and waves",
                           description="What the body does")
    shape_text: StringProperty(name="Shape", default="",
                               description="Optional body description, e.g. 'a tall, heavy-set man'")
    use_seconds: BoolProperty(name="Set length", default=False, description="Fix the motion length")
    seconds: FloatProperty(name="Seconds", default=4.0, min=0.4, max=60.0, precision=1)
    seed: IntProperty(name="Seed", default=0, min=0)
    temperature: FloatProperty(name="Temperature", default=1.0, min=0.0, max=3.0,
                               description="Sampling temperature (0 = always the most likely motion)")
    by_parts: BoolProperty(name="By body part", default=True,
                           description="Two things at once ('jogs, waving') are generated as legs and arms and put "
                                       "together; a named left or right is made the side that moves most")
    use_library: BoolProperty(name="Use Library motions", default=False,
                              description="The Library folder's captioned motions join the candidates for the "
                                          "prompt; one the model's codes cannot carry (a fast kick) is played as "
                                          "captured")
    use_captured: BoolProperty(name="Captured takes", default=True,
                               description="Captured performances of the asked action (the model's motion library) "
                                           "compete with the generated motions and play as captured; off: every "
                                           "motion is generated")
    # the plan of the prompt, shown under it as fields (plan_ui.py)
    plan_segments: CollectionProperty(type=ShapeMovePlanSegment)
    plan_prompt: StringProperty(name="Plan of", default="", description="The prompt the plan was read from")
    plan_base: StringProperty(name="Plan", default="", description="The plan as read (JSON), the fields put into it")
    # shape
    shape_from_text: StringProperty(name="Shape text", default="",
                                    description="e.g. 'a man with a height of 185 cm and a waist circumference of 90 cm'")
    random_scale: FloatProperty(name="Random spread", default=1.0, min=0.0, max=3.0,
                                description="Standard deviation of the random betas")
    auto_redecode: BoolProperty(name="Re-decode motion on shape change", default=True,
                                description="After a shape change, decode the rig's motion tokens again for the new "
                                            "body (feet stay planted, bone lengths match)")
    # retarget
    retarget_source: EnumProperty(
        name="Source", default="FILE",
        items=[("FILE", "File", "A BVH, ASF/AMC or AMASS .npz file"),
               ("ACTION", "Active armature", "The action of the active (non-ShapeMove) armature")])
    retarget_path: StringProperty(name="Motion file", subtype="FILE_PATH", default="")
    retarget_source_fps: FloatProperty(name="Source fps", default=0.0, min=0.0, max=10000.0,
                                       description="The file's frame rate when its own is wrong (BVH Frame Time, "
                                                   "AMC rate); 0 = as the file says")
    retarget_angle_unit: EnumProperty(
        name="Angles", default="FILE",
        items=[("FILE", "As declared", "Degrees or radians as the ASF/AMC declares"),
               ("DEG", "Degrees", "The ASF/AMC's angles are degrees, whatever it declares"),
               ("RAD", "Radians", "The ASF/AMC's angles are radians, whatever it declares")])
    retarget_target: PointerProperty(name="Target rig", type=bpy.types.Object, poll=_is_rig,
                                     description="ShapeMove rig whose body receives the motion (empty: fit a body)")
    # library
    library_folder: StringProperty(name="Library", subtype="DIR_PATH", default="")
    library_query: StringProperty(name="Query", default="")
    library_top_k: IntProperty(name="Results", default=10, min=1, max=100)
    library_results: CollectionProperty(type=ShapeMoveLibraryItem)
    library_index: IntProperty(name="Result", default=0, min=0)
    # train
    train_data: StringProperty(name="Dataset", subtype="DIR_PATH", default="",
                               description="A dataset folder built with `python -m shapemove data build`")
    train_kind: EnumProperty(
        name="Model", default="vae",
        items=[("vae", "SA-VAE", "Shape-aware motion tokenizer"), ("t5", "T5", "Text to shape + motion tokens"),
               ("tma", "TMA", "Text-motion alignment (search, evaluation)")])
    train_model_name: StringProperty(name="Model name", default="my_model",
                                     description="Folder (in the models folder) the trained parts go to")
    train_steps: IntProperty(name="Steps", default=1000, min=1)
    train_config: StringProperty(name="Config", default="small", description="small, paper, tiny or a JSON file")
    train_result: StringProperty(name="Trained model", subtype="DIR_PATH", default="")
    # export
    export_format: EnumProperty(
        name="Format", default="FBX",
        items=[("FBX", "FBX", "Mesh, armature, shape keys and animation"),
               ("GLTF", "glTF (.glb)", "Mesh, skin, morph targets and animation"),
               ("BVH", "BVH", "Skeleton animation only")])


classes = (ShapeMoveObjectProperties, ShapeMoveLibraryItem, ShapeMovePlanSegment, ShapeMoveSceneSettings)


def register():
    bpy.types.Object.shapemove = PointerProperty(type=ShapeMoveObjectProperties)
    bpy.types.Scene.shapemove = PointerProperty(type=ShapeMoveSceneSettings)


def unregister():
    del bpy.types.Scene.shapemove
    del bpy.types.Object.shapemove
