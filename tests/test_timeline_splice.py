"""sequence.splice: a regenerated segment's frames set between the old ones, the neighbours kept."""
import numpy as np
import pytest

from shapemove.core.errors import ShapeMoveError
from shapemove.core.generation.sequence import splice
from shapemove.core.generation.track import rotate_y
from walk_track import walk as _walk


def test_splice_keeps_the_neighbours_and_fades_at_the_seams():
    old = _walk(120, 0.02)                                  # segments 0-40, 40-80, 80-120
    # the middle segment now 40-100, faster and turning: the same frames before it (same codes), a
    # new pace from it on
    new = _walk(140, np.r_[np.full(40, 0.02), np.full(100, 0.05)], turn=np.r_[np.zeros(40), np.full(100, 0.004)])
    out = splice(old, new, 40, 80, 100, blend=6)
    assert len(out) == 140
    np.testing.assert_array_equal(out.joints[:34], old.joints[:34])          # before the first fade: the old frames
    np.testing.assert_array_equal(out.joints[46:94], new.joints[46:94])      # between the fades: the new ones
    tail, old_tail = out.joints[106:], old.joints[86:]
    # after the second fade: the old frames moved rigidly (distances between all joints kept)
    d = lambda j: np.linalg.norm(j[:, :, None] - j[:, None], axis=-1)  # noqa: E731
    np.testing.assert_allclose(d(tail), d(old_tail), atol=1e-9)
    np.testing.assert_allclose(np.diff(tail[:, 0], axis=0), rotate_y(np.diff(old_tail[:, 0], axis=0),
                                                                        np.arctan2(*np.diff(tail[:, 0, [0, 2]], axis=0)[0])
                                                                        - np.arctan2(*np.diff(old_tail[:, 0, [0, 2]], axis=0)[0])),
                               atol=1e-6)
    # no jump anywhere: the largest step is within the two tracks' own steps
    step = np.linalg.norm(np.diff(out.joints, axis=0), axis=-1).max()
    assert step <= 1.5 * max(np.linalg.norm(np.diff(t.joints, axis=0), axis=-1).max() for t in (old, new))
    np.testing.assert_array_equal(out.contacts[:40], old.contacts[:40])
    np.testing.assert_array_equal(out.contacts[100:], old.contacts[80:])


def test_splice_at_the_ends_and_bad_bounds():
    old, new = _walk(80, 0.02), _walk(100, 0.03)
    first = splice(old, new, 0, 40, 60)                     # the first segment changed: no head seam
    np.testing.assert_array_equal(first.joints[:54], new.joints[:54])
    last = splice(old, _walk(90, np.r_[np.full(40, 0.02), np.full(50, 0.03)]), 40, 80, 90)  # the last: no tail seam
    np.testing.assert_array_equal(last.joints[:34], old.joints[:34])
    with pytest.raises(ShapeMoveError, match="splice"):
        splice(old, new, 0, 40, 50)                         # 40 frames after the segment cannot be 50
