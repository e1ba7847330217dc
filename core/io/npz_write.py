"""Write an ``.npz`` whose bytes depend only on its arrays: ``np.savez`` stamps every member with the
current time, so the same motion saved twice gave two different files. Here each member carries
the zip format's earliest date (1980-01-01 00:00:00); the layout is otherwise ``np.savez``'s (one
stored ``NAME.npy`` per array, in the order given, zip64 headers), read by ``np.load`` and
``io/npz_read.py`` alike."""
from __future__ import annotations

import zipfile

import numpy as np

FIXED_DATE = (1980, 1, 1, 0, 0, 0)


def write_npz(file, arrays: dict) -> None:
    """Write ``arrays`` ({name: array}) to ``file`` (a path or a binary file object), no pickles."""
    with zipfile.ZipFile(file, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
        for name, value in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=FIXED_DATE)
            info.compress_type = zipfile.ZIP_STORED
            info.external_attr = 0o600 << 16
            with zf.open(info, "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.asanyarray(value), allow_pickle=False)
