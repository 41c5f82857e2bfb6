"""Boundary conditions resolved to node sets and per-node arrays, for any physics: the fixed
values condensed out, the links, the injected rates and the Robin terms of a network.

Works on the roles of :mod:`yade_electro.network.boundary` (``bc.field('value')``, ...), so a
fixed temperature and a fixed value resolve the same way, and a message names the condition in
its own physics' words (``bc.KIND``).

Units: SI, as the physics says (areas m^2; rates W or A; conductances W/K or S).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError
from ..core.graph import ContactGraph
from ..core.selection import select_nodes

__all__ = ["resolve_nodes", "resolve_area", "ResolvedConditions", "resolve_conditions"]


def resolve_nodes(bc, n: int, graph: Optional[ContactGraph]) -> np.ndarray:
    """Node indices of a boundary condition's ``nodes`` (a selector with a graph, else node
    indices or a mask); BoundaryConditionError when it selects nothing."""
    if getattr(bc, "surface", None) is not None:
        raise BoundaryConditionError(f"{bc.KIND} {bc.name!r} is a surface: resolve it through the model (which "
                                     "knows the container), or give nodes=")
    if graph is not None:
        return select_nodes(graph, bc.nodes, bc.name, bc.KIND)
    if callable(bc.nodes):
        raise BoundaryConditionError(f"{bc.KIND} {bc.name!r}: a selector needs a graph; give node indices or use "
                                     "heat_solver_on_graph")
    a = np.asarray(bc.nodes)
    if a.dtype == bool:
        if a.shape != (n,):
            raise BoundaryConditionError(f"{bc.name!r}: mask has shape {a.shape}, expected ({n},)")
        nodes = np.flatnonzero(a)
    else:
        nodes = np.unique(a.astype(np.int64).reshape(-1))
        if nodes.size and (nodes.min() < 0 or nodes.max() >= n):
            raise BoundaryConditionError(f"{bc.name!r}: node index out of range 0..{n - 1}")
    if nodes.size == 0:
        raise BoundaryConditionError(f"{bc.KIND} {bc.name!r} selects no element")
    return nodes


def resolve_area(bc, nodes, n, default_area) -> np.ndarray:
    """The areas [m^2] of ``bc`` on its ``nodes``: its ``area`` (scalar or one per node of the
    network), else ``default_area`` (the exposed areas)."""
    if bc.area is None:
        if default_area is None:
            raise BoundaryConditionError(f"{bc.KIND} {bc.name!r}: no area given and no graph to estimate the exposed "
                                         "area from; pass area= (m^2, scalar or per node)")
        a = np.asarray(default_area, dtype=float)[nodes]
    else:
        a = np.asarray(bc.area, dtype=float)
        if a.ndim == 0:
            a = np.full(nodes.size, float(a))
        elif a.shape == (n,):
            a = a[nodes]
        else:
            raise BoundaryConditionError(f"{bc.KIND} {bc.name!r}: area must be a scalar or an ({n},) array, got "
                                         f"shape {a.shape}")
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise BoundaryConditionError(f"{bc.KIND} {bc.name!r}: areas must be finite and >= 0 (m^2)")
    return a


@dataclass(frozen=True, eq=False)
class ResolvedConditions:
    """The boundary conditions of a network resolved to node sets and per-node arrays.

    Attributes
    ----------
    fixed_nodes : dict
        name -> node indices held at a fixed value (eliminated).
    links : dict
        name -> (node indices, conductances) of fixed values reached through links.
    fixed : (n,) bool array
        The eliminated nodes (read-only).
    power : (n,) array
        Injected rates (injections and sources), 0 on fixed nodes.
    h_area, h_area_t_inf : (n,) arrays
        Robin ``k A`` and ``k A u_ambient``, 0 on fixed nodes.
    nodes_of : dict
        name -> node indices of every condition.
    terms : dict
        name -> (node indices, per-node values) of each injection (its rates) and Robin
        condition (its ``k A``), 0 on fixed nodes: what each one adds.
    """

    fixed_nodes: dict
    links: dict
    fixed: np.ndarray
    power: np.ndarray
    h_area: np.ndarray
    h_area_t_inf: np.ndarray
    nodes_of: dict
    terms: dict = None


def resolve_conditions(n: int, conditions: Sequence, *, graph: Optional[ContactGraph] = None,
                       default_area=None, nodes_of: Optional[dict] = None, area_of: Optional[dict] = None,
                       link_of: Optional[dict] = None, power=None) -> ResolvedConditions:
    """Resolve the fixed values, injections and Robin conditions of an ``n``-node network (see
    :class:`~yade_electro.network.transient.HeatSolver` for ``nodes_of``, ``area_of``,
    ``link_of`` and ``power``); raises BoundaryConditionError on duplicate names, overlapping
    fixed sets, and areas, conductances or rates that are not finite and >= 0."""
    conditions = list(conditions)
    by_role = {"fixed": [], "injection": [], "robin": []}
    for b in conditions:
        if getattr(b, "ROLE", None) not in by_role:
            raise BoundaryConditionError(f"{getattr(b, 'KIND', type(b).__name__)} {getattr(b, 'name', b)!r} cannot "
                                         "act on this network: give fixed values, injections or Robin conditions")
        by_role[b.ROLE].append(b)
    fixed, injections, robins = by_role["fixed"], by_role["injection"], by_role["robin"]
    names = [b.name for b in conditions]
    if len(set(names)) != len(names):
        raise BoundaryConditionError(f"boundary condition names must be unique, got {names}")
    nodes_of = dict(nodes_of or {})
    area_of, link_of = dict(area_of or {}), dict(link_of or {})

    def nodes(bc):
        if bc.name in nodes_of:
            nd = np.asarray(nodes_of[bc.name], dtype=np.int64)
            if bc.name in area_of or bc.name in link_of:
                return nd                   # aligned with its areas / conductances
            return np.unique(nd)
        return resolve_nodes(bc, n, graph)

    def per_node(table, bc, nd, what):
        a = np.asarray(table[bc.name], dtype=float)
        if a.shape != nd.shape or not np.all(np.isfinite(a)) or np.any(a < 0):
            raise BoundaryConditionError(f"{bc.KIND} {bc.name!r}: {what} must be finite, >= 0 and one per node of "
                                         f"the condition ({nd.size})")
        return a
    owner = np.full(n, -1, dtype=np.int64)
    fixed_nodes = {}
    links = {}
    for k, b in enumerate(fixed):
        if b.name in link_of:
            nd = nodes(b)
            links[b.name] = (nd, per_node(link_of, b, nd, "link conductances"))
            continue
        nd = nodes(b)
        clash = nd[owner[nd] >= 0]
        if clash.size:
            raise BoundaryConditionError(
                f"{clash.size} element(s) are in both {b.KIND}s {fixed[owner[clash[0]]].name!r} and {b.name!r}; "
                "make them disjoint")
        owner[nd] = k
        fixed_nodes[b.name] = nd
    is_fixed = owner >= 0
    is_fixed.setflags(write=False)
    q = np.zeros(n)
    terms = {}
    for b in injections:
        q_before = q.copy()                     # (what this one adds: its term)
        nd = nodes(b)
        rate, density = b.field("rate"), b.field("density")
        if b.name in area_of:
            a = per_node(area_of, b, nd, "areas (m^2)")
            if rate is not None:
                if a.sum() <= 0:
                    raise BoundaryConditionError(f"{b.KIND} {b.name!r}: the areas sum to 0")
                np.add.at(q, nd, rate * a / a.sum())
            else:
                np.add.at(q, nd, density * a)
        elif rate is not None:
            if b.area is None:
                share = np.full(nd.size, 1.0 / nd.size)
            else:
                a = resolve_area(b, nd, n, None)
                if a.sum() <= 0:
                    raise BoundaryConditionError(f"{b.KIND} {b.name!r}: the areas sum to 0")
                share = a / a.sum()
            np.add.at(q, nd, rate * share)
        else:
            np.add.at(q, nd, density * resolve_area(b, nd, n, default_area))
        u = np.unique(nd)
        terms[b.name] = (u, np.where(is_fixed[u], 0.0, (q - q_before)[u]))    # fixed nodes receive nothing
    if power is not None:
        pw = np.asarray(power, dtype=float)
        if pw.shape != (n,) or not np.all(np.isfinite(pw)):
            raise BoundaryConditionError(f"power (sources) must be a finite ({n},) array (per node)")
        q += pw
    hA, hAT = np.zeros(n), np.zeros(n)
    for b in robins:
        nd = nodes(b)
        ha = b.field("coefficient") * (per_node(area_of, b, nd, "areas (m^2)") if b.name in area_of
                                       else resolve_area(b, nd, n, default_area))
        np.add.at(hA, nd, ha)
        np.add.at(hAT, nd, ha * b.field("ambient"))
        terms[b.name] = (nd, np.where(is_fixed[nd], 0.0, ha))
    hA[is_fixed] = 0.0
    hAT[is_fixed] = 0.0
    q[is_fixed] = 0.0
    every = {**fixed_nodes, **{k: v[0] for k, v in links.items()},
             **{b.name: nodes(b) for b in injections + robins}}
    return ResolvedConditions(fixed_nodes=fixed_nodes, links=links, fixed=is_fixed, power=q, h_area=hA,
                              h_area_t_inf=hAT, nodes_of=every, terms=terms)
