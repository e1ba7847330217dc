"""Two things at once (core/data/compose_parts.py): legs and root of a locomotion clip, arms of a
gesture clip, on one body with the feet still planted."""
import json
import shutil

import numpy as np

from shapemove.core.data import compose_parts as cp
from shapemove.core.geometry.rotations import axis_angle_to_matrix


def test_legs_of_a_walk_with_the_arms_of_a_wave(tiny_dataset, tmp_path, openbody):
    data = tmp_path / "d"
    shutil.copytree(tiny_dataset, data)
    for p in (data / "meta").glob("*.json"):
        m = json.loads(p.read_text())
        m["split"] = "train"
        p.write_text(json.dumps(m))
    written = cp.compose_parts_dataset(data, 6, seed=0, body=openbody, verbose=False)
    assert len(written) == 6
    for cid in written:
        meta = json.loads((data / "meta" / f"{cid}.json").read_text())
        legs, arms = meta["composed_from"]
        parts = meta["labels"]["parts"]
        assert parts["legs"] in cp.LEGS_ACTIONS and parts["arms"] in cp.ARMS_ACTIONS
        assert (parts["legs"], parts["arms"]) not in cp.HELD_OUT_PAIRS
        caps = (data / "texts" / f"{cid}.txt").read_text().lower()
        assert " while " in caps or " as " in caps or "same time" in caps
        rot = axis_angle_to_matrix(np.load(data / "poses" / f"{cid}.npy"))
        ra = axis_angle_to_matrix(np.load(data / "poses" / f"{legs}.npy"))
        rb = axis_angle_to_matrix(np.load(data / "poses" / f"{arms}.npy"))
        n = len(rot)
        # the legs are a window of A's, the arms a window of B's (same length)
        starts_a = [s for s in range(len(ra) - n + 1) if np.allclose(ra[s:s + n, [1, 2, 4, 5, 7, 8]], rot[:, [1, 2, 4, 5, 7, 8]], atol=1e-4)]
        starts_b = [s for s in range(len(rb) - n + 1) if np.allclose(rb[s:s + n, cp.ARM_JOINTS], rot[:, cp.ARM_JOINTS], atol=1e-4)]
        assert starts_a and starts_b
        # feet planted: on A's contact frames the contact joints barely move horizontally
        j = np.load(data / "new_joints" / f"{cid}.npy")
        c = np.load(data / "contacts" / f"{cid}.npy")
        feet = j[:, [7, 8, 10, 11]][:, :, [0, 2]]
        step = np.linalg.norm(np.diff(feet, axis=0), axis=-1)
        on = c[:-1] & c[1:]
        assert on.sum() > 5 and step[on > 0].mean() < 0.01        # < 1 cm/frame while planted
