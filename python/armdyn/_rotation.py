"""Rotation helpers on Euler parameters (unit quaternions, scalar first ``[e0, e1, e2, e3]``)."""

from __future__ import annotations

import numpy as np


def quat_to_rot(e) -> np.ndarray:
    """The rotation matrix (body → world) of the Euler parameters ``e``: (4,) gives (3, 3),
    (..., 4) gives (..., 3, 3)."""
    e0, e1, e2, e3 = np.moveaxis(np.asarray(e, dtype=float), -1, 0)
    rows = (
        (1 - 2 * (e2 * e2 + e3 * e3), 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)),
        (2 * (e1 * e2 + e0 * e3), 1 - 2 * (e1 * e1 + e3 * e3), 2 * (e2 * e3 - e0 * e1)),
        (2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), 1 - 2 * (e1 * e1 + e2 * e2)),
    )
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)
