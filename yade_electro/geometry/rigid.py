"""Rigid motions of point sets: the best rotation and translation between two placements of
the same points (Kabsch), and a moved solid's elements taken back to the frame its container
is given in.

A bonded solid's container (:class:`~yade_electro.geometry.shapes.Shape`) stays where it was
given while YADE may move the solid as a whole; tessellations bounded by the container are
therefore made in the container's frame, with the elements taken back by the solid's rigid
motion since the last tessellation (:func:`back_to_reference`). Cell volumes and face areas do
not change under a rigid motion; lengths are taken from the current positions.

Units: m.
"""
from __future__ import annotations

from typing import Optional

import numpy as np

__all__ = ["rigid_pose", "back_to_reference"]


def rigid_pose(reference, current):
    """(R, t) of the rigid motion ``current ~ reference @ R.T + t`` (least squares, Kabsch)."""
    P, Q = np.asarray(reference, float), np.asarray(current, float)
    pc, qc = P.mean(axis=0), Q.mean(axis=0)
    U, _, Vt = np.linalg.svd((P - pc).T @ (Q - qc))
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R = Vt.T @ D @ U.T
    return R, qc - pc @ R.T


def back_to_reference(ref_ids, ref_pos, ids, pos, tolerance: float) -> Optional[np.ndarray]:
    """``pos`` (n, 3) [m] of the elements ``ids`` taken back by the rigid motion that best
    carries the elements common to both sets from ``ref_pos`` (placed as ``ref_ids``) to
    ``pos``; None when that motion moves no element by more than ``tolerance`` [m] or fewer
    than 4 elements are common (nothing to take back)."""
    ref_ids, ids = np.asarray(ref_ids, np.int64), np.asarray(ids, np.int64)
    _, i_ref, i_now = np.intersect1d(ref_ids, ids, assume_unique=True, return_indices=True)
    if i_ref.size < 4:
        return None
    P, Q = np.asarray(ref_pos, float)[i_ref], np.asarray(pos, float)[i_now]
    R, t = rigid_pose(P, Q)
    if float(np.max(np.linalg.norm(P @ R.T + t - P, axis=1))) <= tolerance:
        return None
    return (np.asarray(pos, float) - t) @ R
