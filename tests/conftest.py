"""Shared fixtures. Tests that need the motion-capture archives use ``mocap_root``: they skip
with a reason when the archives are absent, and fail instead when SHAPEMOVE_REQUIRE_DATA=1 (CI)."""
from __future__ import annotations

import os

import pytest

REQUIRE_DATA = os.environ.get("SHAPEMOVE_REQUIRE_DATA") == "1"


def need_data(reason: str):
    if REQUIRE_DATA:
        pytest.fail(f"SHAPEMOVE_REQUIRE_DATA=1 but {reason}")
    pytest.skip(reason)


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
