"""A model folder missing a part (issue 28): ``tma/tma.pt`` gone from a folder whose manifest lists
it is an error naming the file; a folder that never had one still generates, and every motion it
makes carries a warning (printed by the CLI, shown by the panel) that best-of-N picking is off."""
from __future__ import annotations

import shutil

import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.model_bundle import DEFAULT_MODEL_DIR, model_files, part_warnings
from shapemove.core.model_files import write_manifest

pytestmark = pytest.mark.usefixtures("one_thread")


@pytest.fixture(scope="module")
def default_model():
    if not (DEFAULT_MODEL_DIR / "tma" / "tma.pt").is_file():
        pytest.skip("the default model is not built")
    return DEFAULT_MODEL_DIR


def _copy(src, dst, with_tma: bool):
    dst.mkdir()
    shutil.copy2(src / "savae.pt", dst / "savae.pt")
    shutil.copytree(src / "t5", dst / "t5")
    if with_tma:
        shutil.copytree(src / "tma", dst / "tma")
    return dst


def test_listed_part_gone_is_an_error_naming_it(default_model, tmp_path):
    d = _copy(default_model, tmp_path / "m", with_tma=True)
    write_manifest(d)
    assert model_files(d)["tma"].is_file() and part_warnings(d) == []
    (d / "tma" / "tma.pt").unlink()
    with pytest.raises(ShapeMoveError, match="tma/tma.pt is missing \\(listed in .*manifest.json\\).*best-of-N"):
        model_files(d)


def test_folder_without_tma_warns_on_every_motion(default_model, tmp_path):
    from shapemove.core.generation.generate import Generator

    d = _copy(default_model, tmp_path / "m", with_tma=False)
    (w,) = part_warnings(d)
    assert str(d / "tma" / "tma.pt") in w and "best-of-N picking is off" in w
    gen = Generator(d)
    assert gen.picker is None
    motion = gen.generate("a person walks forward", betas=[0.0] * 10, seconds=2.0, seed=1)
    assert w in motion.warnings
    # one sample asked for: nothing is lost, nothing is said
    from shapemove.core.generation.generate import Request

    (one,) = gen.generate_batch([Request("a person walks forward", None, [0.0] * 10, 2.0, 1, 1.0, 50,
                                         candidates=1)])
    assert w not in one.warnings
