"""Train/val/test split by subject where the data has several subjects, else by a stable hash.

HDM05 has four actors and CMU one subject per folder, so whole actors/subjects are held out:
that tests generalisation to unseen bodies. Bandai is one actor on one skeleton, so its clips are
split by a hash of the clip id (a rebuild or an added source never moves a clip between splits).
Augmented copies always follow the split of the clip they were made from. DeepMimic's 29 clips are
all training data: most actions (cartwheel, backflip, crawl, ...) have that one clip only, and the
long walks come with mirrored copies that a hash split would put on both sides.
"""
from __future__ import annotations

import hashlib

HELD_OUT_SUBJECTS = {
    "hdm05-dg": "test",
    "cmu-09": "test",
    "cmu-13": "val",
}


def _hash_fraction(key: str) -> float:
    return int(hashlib.sha1(key.encode()).hexdigest()[:8], 16) / 0xFFFFFFFF


def split_of(clip_id: str, subject: str, dataset: str, test_frac: float = 0.1, val_frac: float = 0.05) -> str:
    if subject in HELD_OUT_SUBJECTS:
        return HELD_OUT_SUBJECTS[subject]
    if dataset in ("hdm05", "cmu", "deepmimic"):  # DeepMimic: one clip per action (and mirrored copies)
        return "train"
    u = _hash_fraction(clip_id)
    if u < test_frac:
        return "test"
    if u < test_frac + val_frac:
        return "val"
    return "train"
