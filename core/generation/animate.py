"""One entry for the animation options of a request (command line, worker job, batch file):
loop, in place, along a path, speed / stretch. See docs/animation.md.

Order: the motion is made (``loop.generate_loop`` for a loop, ``path_follow`` for a path, else the
generator), then played at ``speed`` or stretched to ``stretch`` seconds (``time_warp``), then walked
along the path, and last held in place (``in_place``). Combinations that contradict each other
are refused before anything is generated; where an option overrides what the words ask (a loop and
"in a circle"), the motion's notes say which won (``plan/option_conflicts.py``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ShapeMoveError
from ..plan.option_conflicts import option_notes
from ..scene.motion_file import Motion
from .time_warp import check_seconds, check_speed


@dataclass
class Animation:
    loop: bool = False
    in_place: bool = False
    path: np.ndarray | None = None    # (N,2) [x, z] metres
    speed: float | None = None        # 0.5..2
    stretch: float | None = None      # seconds

    @property
    def any(self) -> bool:
        return self.loop or self.in_place or self.path is not None or self.speed is not None or self.stretch is not None


def check_animation(a: Animation) -> Animation:
    from .polyline import check_path

    if a.speed is not None:
        a.speed = check_speed(a.speed)
        if a.speed == 1.0:
            a.speed = None
    if a.stretch is not None:
        a.stretch = check_seconds(a.stretch)
    if a.speed is not None and a.stretch is not None:
        raise ShapeMoveError("give --speed or --stretch, not both")
    if a.path is not None:
        a.path = check_path(a.path)
        if a.loop:
            raise ShapeMoveError("--loop and --path do not go together: a path has a start and an end")
        if a.in_place:
            raise ShapeMoveError("--in-place and --path do not go together: in place removes the travel a path needs")
        if a.stretch is not None:
            raise ShapeMoveError("--stretch and --path do not go together: the path sets the length (or give --seconds)")
    return a


def animation_from(params: dict) -> Animation:
    """Options from a JSON object (batch line, worker params): "loop", "in_place", "path"
    ([[x, z], ...] or a file name), "speed", "stretch"."""
    from .path_follow import read_path
    from .polyline import check_path

    path = params.get("path")
    if isinstance(path, str):
        path = read_path(path)
    elif path is not None:
        path = check_path(path)
    for key in ("loop", "in_place"):
        if params.get(key) is not None and not isinstance(params.get(key), bool):
            raise ShapeMoveError(f'"{key}" must be true or false, got {params.get(key)!r}')
    return check_animation(Animation(loop=bool(params.get("loop")), in_place=bool(params.get("in_place")), path=path,
                                     speed=params.get("speed"), stretch=params.get("stretch")))


def animate(gen, req, a: Animation, progress=None, cancel=None) -> Motion:
    """``req`` (a ``generate.Request``) made with the options ``a``."""
    from .in_place import in_place
    from .loop import generate_loop
    from .path_follow import generate_along_path
    from .time_warp import time_warp

    a = check_animation(a)
    if a.loop:
        motion = generate_loop(gen, req, progress, cancel)
    elif a.path is not None:
        motion = generate_along_path(gen, req, a.path, progress=progress, speed=a.speed)
    else:
        out = gen.generate_batch([req], progress=progress, cancel=cancel)
        if not out:
            raise ShapeMoveError("cancelled")
        motion = out[0]
    keep = (motion.warnings, motion.shape_source, motion.prompt_check, motion.notes, motion.provenance, motion.plan)
    if a.path is None and (a.speed is not None or a.stretch is not None):
        motion = time_warp(motion, gen.body, speed=a.speed, seconds=a.stretch, ik_refine_iters=gen.ik_refine_iters)
    if a.in_place:
        motion = in_place(motion)
    motion.warnings = list(keep[0]) + [w for w in motion.warnings if w not in keep[0]]
    motion.shape_source, motion.prompt_check, motion.notes = keep[1], keep[2], list(keep[3])
    motion.provenance = motion.provenance or keep[4]   # a captured take stays captured through the edits
    motion.plan = keep[5]
    if req.by_parts:   # the words an option overrides, said (plan/option_conflicts.py)
        motion.notes += option_notes(req.prompt, loop=a.loop, in_place=a.in_place, path=a.path is not None,
                                     seconds=req.seconds)
    return motion
