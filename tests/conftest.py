"""Shared fixtures. Tests that need the motion-capture archives use ``mocap_root``: they skip
with a reason when the archives are absent, and fail instead when SHAPEMOVE_REQUIRE_DATA=1 (CI)."""
from __future__ import annotations

import importlib
import os

import pytest

try:  # small tensors: one thread is faster and keeps parallel test processes from oversubscribing 2 cores
    import torch

    torch.set_num_threads(1)
except ImportError:  # pragma: no cover
    pass

REQUIRE_DATA = os.environ.get("SHAPEMOVE_REQUIRE_DATA") == "1"
# run in their own process by blender_inside.run (bpy must start with a temporary user folder)
collect_ignore = ["in_blender"]


def need_data(reason: str):
    if REQUIRE_DATA:
        pytest.fail(f"SHAPEMOVE_REQUIRE_DATA=1 but {reason}")
    pytest.skip(reason, allow_module_level=True)


def need_module(name: str, reason: str | None = None):
    """Import a module a test needs: skip with a reason when it is missing, fail instead when
    SHAPEMOVE_REQUIRE_DATA=1 (CI installs everything, so a missing module there is a failure)."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:
        need_data(reason or f"needs the Python module {name!r} ({exc})")


@pytest.fixture()
def addon():
    """The extension registered in a factory-fresh scene of the real bpy (skipped without bpy), and
    unregistered after the test."""
    bpy = pytest.importorskip("bpy", reason="needs the bpy module (pip install bpy==5.0.1)")
    import shapemove

    bpy.ops.wm.read_factory_settings(use_empty=True)
    shapemove.register()
    yield
    shapemove.unregister()
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.fixture(scope="module")
def one_thread():
    """Tiny models on a shared 2-core machine: intra-op threads only add contention (up to 10x slower).
    A module opts in with ``pytestmark = pytest.mark.usefixtures("one_thread")``."""
    from shapemove.core.torch_threads import one_torch_thread

    with one_torch_thread():
        yield


@pytest.fixture(scope="session")
def mocap_root():
    """Path with bandai/, hdm05/, cmu/ unpacked from ../shared/data (once, into .cache/mocap)."""
    from shapemove.core.errors import ShapeMoveError
    from shapemove.core.io.archive import mocap_root as _root

    try:
        return _root()
    except ShapeMoveError as exc:
        need_data(str(exc))


@pytest.fixture(scope="session")
def openbody():
    from shapemove.core.body.openbody import OpenBody

    return OpenBody.load()


# A handful of real clips from each archive, built with the real dataset builder: the shared
# input of the training/eval tests. Built once per test session (about 10-20 s).
TINY_CLIPS = [
    "dataset-1_walk_feminine_001", "dataset-1_run_happy_001", "dataset-2_wave-left-hand_elderly_001",
    "dataset-2_walk_masculine_003", "dataset-1_kick_normal_001", "dataset-2_run_elderly_001",
    "HDM_bd_kickLFront1Reps_001_120", "HDM_dg_squat1Reps_025_120", "HDM_bk_jogLeftCircle4StepsRstart_003_120",
    "cmu_02_01", "cmu_09_01", "cmu_13_10",
]


@pytest.fixture(scope="session")
def tiny_dataset(mocap_root, tmp_path_factory):
    from shapemove.core.data.build import build_dataset

    out = tmp_path_factory.mktemp("tiny_dataset")
    report = build_dataset([mocap_root], out, only=TINY_CLIPS, augment_share=0.5, verbose=False)
    assert report.built >= len(TINY_CLIPS) - 2, report.summary()
    return out
