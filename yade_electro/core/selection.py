"""Choosing elements: selectors for electrodes and boundary conditions, checked at once, and a
membership fixed by element id.

A selector is one of

* a callable ``f(pos (n, 3), radius (n,)) -> bool mask`` (``yade_electro.yade`` turns YADE
  predicates into such callables: selection by element centre);
* a boolean mask over the graph's nodes;
* a sequence of ids (YADE body ids) of nodes of the graph, integers only.

:func:`check_selector` refuses anything else when the model is built (a float id such as 3.7
is not silently taken as 3). :class:`Membership` resolves a selector once, on the first graph,
and keeps the *ids* it selected: elements do not join or leave an electrode or a boundary
condition as they move. ``reselect=True`` re-evaluates the selector on every new structure
instead (the explicit option for selections that should follow the geometry).
"""
from __future__ import annotations

import numbers
from typing import Callable, Optional, Sequence, Union

import numpy as np

from .errors import BoundaryConditionError
from .graph import ContactGraph

__all__ = ["Selector", "check_selector", "select_nodes", "Membership"]

Selector = Union[Sequence[int], np.ndarray, Callable]


def check_selector(select, what: str = "selector") -> None:
    """Raise BoundaryConditionError unless ``select`` is a callable, a boolean mask or a
    sequence of integer ids (``what`` names it in the message)."""
    if callable(select):
        return
    if select is None or isinstance(select, (str, bytes, dict)):
        raise BoundaryConditionError(f"{what}: give a YADE predicate, a callable f(pos, radius) -> mask, a "
                                     f"boolean mask or a list of body ids; got {select!r}")
    if isinstance(select, numbers.Number) and not isinstance(select, (bool, np.bool_)):
        select = [select]
    try:
        arr = np.asarray(select)
    except Exception:
        raise BoundaryConditionError(f"{what}: cannot read {select!r} as ids or a mask") from None
    if arr.dtype == bool:
        if arr.ndim != 1:
            raise BoundaryConditionError(f"{what}: a mask must be one-dimensional, got shape {arr.shape}")
        return
    if arr.dtype == object or arr.ndim != 1:
        raise BoundaryConditionError(f"{what}: body ids must be a flat list of integers, got {select!r}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        bad = arr
        if np.issubdtype(arr.dtype, np.floating):
            ok = np.isfinite(arr) & (arr == np.round(arr))
            if np.all(ok):
                return                  # 3.0 is the id 3
            bad = arr[~ok]
        raise BoundaryConditionError(f"{what}: body ids must be integers, got {bad[:5].tolist()} (a selection "
                                     "by position is a predicate such as pack.inAlignedBox(...))")


def select_nodes(graph: ContactGraph, select: Selector, name: str = "?", what: str = "electrode") -> np.ndarray:
    """Node indices of ``graph`` chosen by ``select`` (see module doc); raises
    BoundaryConditionError when it is malformed or selects nothing. ``what`` and ``name``
    name it in messages (``electrode 'top'``, ``thermal boundary condition 'hot'``)."""
    label = f"{what} {name!r}"
    check_selector(select, label)
    if callable(select):
        mask = np.asarray(select(graph.pos, graph.radius), dtype=bool)
        if mask.shape != (graph.n_nodes,):
            raise BoundaryConditionError(f"{label}: the selector returned shape {mask.shape}, "
                                         f"expected a mask of ({graph.n_nodes},)")
        nodes = np.flatnonzero(mask)
    else:
        if isinstance(select, numbers.Number) and not isinstance(select, (bool, np.bool_)):
            select = [select]
        arr = np.asarray(select)
        if arr.dtype == bool:
            if arr.shape != (graph.n_nodes,):
                raise BoundaryConditionError(f"{label}: mask has shape {arr.shape}, the graph "
                                             f"has {graph.n_nodes} elements")
            nodes = np.flatnonzero(arr)
        elif arr.size == 0:
            nodes = np.zeros(0, dtype=np.int64)
        else:
            try:
                nodes = graph.index_of(arr.astype(np.int64))
            except Exception as exc:
                raise BoundaryConditionError(f"{label}: {exc} (ids must be spherical bodies of the "
                                             "packing)") from None
    if nodes.size == 0:
        raise BoundaryConditionError(f"{label} selects no element: check its region/ids against the "
                                     "packing (selection is by element centre)")
    return nodes


class Membership:
    """The elements a selector chose, kept by id.

    Parameters
    ----------
    name : str
        For messages (an electrode or boundary-condition name).
    select : Selector
    reselect : bool
        Evaluate ``select`` again on each new structure (default: once, then by id).
    what : str
        What it selects for, in messages ('electrode', 'thermal boundary condition').
    """

    def __init__(self, name: str, select: Selector, reselect: bool = False, what: str = "electrode"):
        check_selector(select, f"{what} {name!r}")
        self.name, self.select, self.reselect, self.what = name, select, bool(reselect), what
        self.ids: Optional[np.ndarray] = None

    def nodes(self, graph: ContactGraph) -> np.ndarray:
        """Node indices on ``graph`` (first call, or ``reselect``: from the selector)."""
        if self.ids is None or self.reselect:
            nodes = select_nodes(graph, self.select, self.name, self.what)
            self.ids = graph.ids[nodes].copy()
            return nodes
        present = np.isin(self.ids, graph.ids)
        if not np.any(present):
            raise BoundaryConditionError(f"{self.what} {self.name!r}: none of its {self.ids.size} element(s) is left in the "
                                         "packing (erased bodies?)")
        return np.unique(graph.index_of(self.ids[present]))

    def restore(self, ids) -> "Membership":
        """Fix the membership to these ids (a resumed run)."""
        self.ids = np.asarray(ids, dtype=np.int64).copy()
        return self
