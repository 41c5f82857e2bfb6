"""Resolved grains in an engine (issue 35; numpy only): the conductance law ``'grains'``, whose
network is each grain's own bonded sub-packing plus the links across the contacts between
grains, found again as the grains move.

A scene's grains are kept in a :class:`GrainSet`: for each grain its
:class:`~yade_electro.network.grains.GrainTemplate` and the body ids of its elements in the
template's order (in YADE: a clump of the template's spheres,
:func:`yade_electro.yade.grains.add_grain`). On a graph of those elements
(``Reader(bonds='contacts', clumps='resolved')``) the law

* poses each grain by Kabsch from its elements' positions (:func:`rigid_pose`; a grain whose
  elements do not move rigidly is an error);
* keeps each grain's template edges, with the template's factors ``g = A / l`` [m] (the
  'voronoi' law inside the grain's shape) and cell volumes [m^3] (the capacities);
* takes the pairs of grains that the graph's candidate pairs join (members of two grains
  within the reader's skin), and links their elements across the contact
  (:func:`~yade_electro.network.grains.grain_contact_geometry`, in the first grain's frame:
  a rigid motion of the pair changes no link), with the factor ``A_ij / (d_i + d_j)`` [m] of
  the two half cells and, in series, the contact resistance ``R_c / A_ij`` [K/W]
  (:meth:`GrainLaw.thermal_series`) and electrically a film ``film / A_ij`` [ohm]
  (:meth:`GrainLaw.film_resistance`).

``R_c`` [m^2 K/W] is a number, or ``f(pressure [Pa]) -> R_c`` with the pressure the normal
force between the two grains (``normal_force``, from the DEM) over the contact's patch area
(e.g. :func:`~yade_electro.network.grain_contact.mikic_resistance`); a contact that carries no
force conducts nothing under a pressure law. A contact's links are kept while its relative
pose moves less than ``reuse`` times the smallest element radius (any point of the second
grain, seen from the first); the network changes as grains move (:attr:`GrainLaw.moves_network`).

Units: m, m^2, m^3, m^2 K/W, ohm m^2, N, Pa.
"""
from __future__ import annotations

from typing import Callable, Dict, Optional, Tuple

import numpy as np

from ..core.errors import BoundaryConditionError, GraphError
from ..laws.factors import ContactLaw, register_conductance_law
from .grain_contact import contact_resistance_value
from .grains import GrainTemplate, grain_contact_geometry, rigid_pose

__all__ = ["GrainSet", "GrainLaw"]


class GrainSet:
    """The resolved grains of a scene, in the order they were added: each a template and its
    elements' body ids in the template's order. Built once, grain by grain (:meth:`add`)."""

    def __init__(self):
        self.templates: list = []          # distinct templates
        self.template_of: list = []        # grain -> index in templates
        self.members: list = []            # grain -> (n,) body ids, template order
        self._sorted = None

    @property
    def n(self) -> int:
        return len(self.members)

    def add(self, template: GrainTemplate, body_ids) -> int:
        """Add a grain of ``template`` whose elements are the bodies ``body_ids`` (template
        order); returns the grain's index."""
        if not isinstance(template, GrainTemplate):
            raise TypeError(f"a grain's template is a GrainTemplate (yade_electro.packing.grains.grain_template), "
                            f"got {template!r}")
        ids = np.asarray(body_ids, np.int64).ravel()
        if ids.size != template.n:
            raise ValueError(f"a grain of this template has {template.n} elements, got {ids.size} body ids")
        taken = np.intersect1d(ids, np.concatenate(self.members)) if self.members else ids[:0]
        if taken.size or np.unique(ids).size != ids.size:
            raise ValueError(f"bodies {sorted(set(taken.tolist()))[:5] or 'repeated'} are already elements of a grain")
        for k, t in enumerate(self.templates):
            if t is template:
                self.template_of.append(k)
                break
        else:
            self.templates.append(template)
            self.template_of.append(len(self.templates) - 1)
        self.members.append(ids)
        self._sorted = None
        return self.n - 1

    def template(self, grain: int) -> GrainTemplate:
        return self.templates[self.template_of[grain]]

    def locate(self, ids) -> Tuple[np.ndarray, np.ndarray]:
        """(grain, element) of each body id of ``ids`` (-1, -1 for a body of no grain)."""
        if self._sorted is None:
            all_ids = np.concatenate(self.members) if self.members else np.zeros(0, np.int64)
            grain = np.repeat(np.arange(self.n), [m.size for m in self.members])
            element = np.concatenate([np.arange(m.size) for m in self.members]) if self.members else grain
            order = np.argsort(all_ids, kind="stable")
            self._sorted = (all_ids[order], grain[order], element[order])
        keys, grain, element = self._sorted
        ids = np.asarray(ids, np.int64)
        g, e = np.full(ids.size, -1, np.int64), np.full(ids.size, -1, np.int64)
        if keys.size:
            at = np.minimum(np.searchsorted(keys, ids), keys.size - 1)
            hit = keys[at] == ids
            g[hit], e[hit] = grain[at[hit]], element[at[hit]]
        return g, e


@register_conductance_law("grains")
class GrainLaw(ContactLaw):
    """The conductance law of resolved grains (module doc).

    Parameters
    ----------
    grains : GrainSet
        The scene's grains (every element of the graph must be one grain's).
    contact_resistance : float or callable
        R_c [m^2 K/W] >= 0 of the contacts between grains, or ``f(pressure [Pa]) -> R_c``
        (then ``normal_force`` is needed).
    film : float
        Electrical: a film's specific resistance [ohm m^2] across the contacts (default 0).
    normal_force : callable, optional
        ``f(pairs (k, 2) of grain indices) -> (k,)`` normal forces [N] between those grains now.
    samples : int
        Sample points of a contact's patch (its face areas).
    reuse : float
        A contact's links are kept while its relative pose moves less than ``reuse`` times the
        smallest element radius.
    radius, stiffness_ratio, correction
        Of the element-to-wall contacts (the 'contact' law's, sphere on plane).
    """

    name = "grains"
    needs_container = False
    moves_network = True
    clumps = "resolved"          # the reader's clump mode: every element read, grain by grain

    def __init__(self, grains: GrainSet = None, contact_resistance=None, film: float = 0.0,
                 normal_force: Optional[Callable] = None, samples: int = 20_000, reuse: float = 1e-3,
                 radius: str = "geometric", stiffness_ratio: float = 1.0, correction: str = "hertz"):
        super().__init__(radius, stiffness_ratio, correction, film)
        if not isinstance(grains, GrainSet) or grains.n == 0:
            raise ValueError("the 'grains' law needs grains=<a GrainSet with the scene's grains> (in YADE: "
                             "yade_electro.yade.grains.add_grain adds each grain and fills it)")
        if contact_resistance is None:
            raise ValueError("the 'grains' law needs contact_resistance= (m^2 K/W, a number >= 0, or "
                             "f(pressure in Pa) -> m^2 K/W)")
        if callable(contact_resistance):
            if normal_force is None:
                raise ValueError("a pressure-dependent contact_resistance needs the grains' normal forces: make the "
                                 "law with yade_electro.yade.grains.grain_law (it reads them from YADE), or give "
                                 "normal_force=f(grain pairs) -> N")
        else:
            contact_resistance = contact_resistance_value(contact_resistance)
        if not (isinstance(samples, (int, np.integer)) and samples >= 100):
            raise ValueError(f"samples must be an integer >= 100, got {samples!r}")
        if not (np.isfinite(reuse) and reuse >= 0):
            raise ValueError(f"reuse must be finite and >= 0 (a fraction of the smallest element radius), got {reuse!r}")
        self.grains, self.contact_resistance, self.normal_force = grains, contact_resistance, normal_force
        self.samples, self.reuse = int(samples), float(reuse)
        self._cache: Dict[tuple, tuple] = {}      # (grain i, grain j) -> (relative pose, geometry)
        self._made = None                          # the last network: (graph, edges, keys, factor, link area, pairs)
        #: contacts of the last network: {(grain i, grain j): patch area [m^2]}
        self.contacts: Dict[Tuple[int, int], float] = {}
        #: contact geometries computed (not reused) so far
        self.contact_computations = 0

    # -- the network -----------------------------------------------------------------------
    def _nodes(self, graph):
        """(grain of each node, node index of each grain's elements (list))."""
        g, e = self.grains.locate(graph.ids)
        stray = np.asarray(graph.ids)[g < 0]
        if stray.size:
            raise GraphError(f"bodies {stray[:8].tolist()}{' ...' if stray.size > 8 else ''} are elements of no "
                             "grain: the 'grains' law conducts through grains only (add them with "
                             "yade_electro.yade.grains.add_grain, or leave them out of the reader's mask)")
        nodes = []
        for k in range(self.grains.n):
            at = np.full(self.grains.template(k).n, -1, np.int64)
            mine = np.flatnonzero(g == k)
            at[e[mine]] = mine
            if np.any(at < 0):
                missing = self.grains.members[k][at < 0]
                raise GraphError(f"grain {k}: its elements {missing[:8].tolist()} are not in the scene's graph; a "
                                 "grain conducts whole (read clumps: Reader(bonds='contacts', clumps='resolved'))")
            nodes.append(at)
        return g, nodes

    def poses(self, graph) -> list:
        """(R, t) of every grain on ``graph``; GraphError when a grain has not moved rigidly."""
        _, nodes = self._nodes(graph)
        return self._poses(graph, nodes)

    def _poses(self, graph, nodes):
        out = []
        for k, at in enumerate(nodes):
            tmpl = self.grains.template(k)
            R, t = rigid_pose(tmpl.centres, graph.pos[at])
            misfit = float(np.max(np.linalg.norm(tmpl.placed(R, t) - graph.pos[at], axis=1)))
            if misfit > 1e-6 * float(tmpl.radii.min()) + 1e-12:
                raise GraphError(f"grain {k} has not moved as a rigid body (its elements are up to {misfit:.3g} m "
                                 "off the best rigid pose): a grain is one clump of its template's spheres")
            out.append((R, t))
        return out

    def _contact(self, i, j, poses):
        (Ri, ti), (Rj, tj) = poses[i], poses[j]
        rel = (Ri.T @ Rj, (tj - ti) @ Ri)
        kept = self._cache.get((i, j))
        if kept is not None:
            (R0, t0), geometry = kept
            tj_ = self.grains.template(j)
            reach = float(np.max(np.linalg.norm(tj_.centres, axis=1)))
            moved = np.linalg.norm(rel[0] - R0, 2) * reach + np.linalg.norm(rel[1] - t0)
            limit = self.reuse * min(float(self.grains.template(i).radii.min()), float(tj_.radii.min()))
            if moved <= limit:
                return geometry
        geometry = grain_contact_geometry(self.grains.template(i), poses[i], self.grains.template(j), poses[j],
                                          self.samples)
        self.contact_computations += 1
        self._cache[(i, j)] = (rel, geometry)
        return geometry

    def network(self, graph) -> np.ndarray:
        made = self._made
        if made is not None and made[0] is graph:
            return made[1]
        g, nodes = self._nodes(graph)
        poses = self._poses(graph, nodes)
        edges, factor, area, grain_pair = [], [], [], []
        for k, at in enumerate(nodes):
            tmpl = self.grains.template(k)
            edges.append(at[tmpl.edges])
            factor.append(tmpl.factor)
            area.append(np.zeros(tmpl.edges.shape[0]))
            grain_pair.append(np.full((tmpl.edges.shape[0], 2), -1, np.int64))
        ge = g[np.asarray(graph.edges, np.int64)] if len(graph.edges) else np.zeros((0, 2), np.int64)
        ge = np.sort(ge[ge[:, 0] != ge[:, 1]], axis=1)
        contacts = {}
        for i, j in np.unique(ge, axis=0) if ge.size else ():
            i, j = int(i), int(j)
            pairs, A, da, db, patch = self._contact(i, j, poses)
            if not pairs.size:
                continue
            contacts[(i, j)] = patch
            edges.append(np.column_stack([nodes[i][pairs[:, 0]], nodes[j][pairs[:, 1]]]))
            factor.append(A / (da + db))
            area.append(A)
            grain_pair.append(np.tile([i, j], (A.size, 1)))
        near = {tuple(p) for p in ge.tolist()}
        for key in [k for k in self._cache if k not in near]:
            del self._cache[key]                 # apart: made again when they meet
        edges = np.concatenate(edges).astype(np.int64)
        keys = edges[:, 0] * graph.n_nodes + edges[:, 1]
        self._made = (graph, edges, keys, np.concatenate(factor), np.concatenate(area),
                      np.concatenate(grain_pair), contacts)
        self.contacts = contacts
        return edges

    def _lookup(self, graph, edges):
        """Rows of the last network for ``edges`` (-1 for an edge it does not have)."""
        if self._made is None or self._made[0] is not graph:
            self.network(graph)
        made_edges, keys = self._made[1], self._made[2]
        edges = made_edges if edges is None else np.asarray(edges, np.int64)
        if edges is made_edges:
            return np.arange(keys.size)
        want = edges[:, 0] * graph.n_nodes + edges[:, 1]
        order = np.argsort(keys)
        at = np.minimum(np.searchsorted(keys[order], want), keys.size - 1)
        rows = order[at]
        return np.where(keys[rows] == want, rows, -1)

    def factor(self, graph, edges=None) -> np.ndarray:
        """``g`` [m] of ``edges``: the template's inside a grain, ``A_ij / (d_i + d_j)`` across a
        contact (0 for an edge of no current link)."""
        rows = self._lookup(graph, edges)
        return np.where(rows >= 0, self._made[3][np.maximum(rows, 0)], 0.0)

    def _per_area(self, rows, specific) -> np.ndarray:
        """``specific / A_ij`` on the rows of the last network that are contact links (0 elsewhere)."""
        A = np.where(rows >= 0, self._made[4][np.maximum(rows, 0)], 0.0)
        out = np.zeros(rows.size)
        link = A > 0
        out[link] = np.asarray(specific, float)[link] / A[link] if np.ndim(specific) else specific / A[link]
        return out

    def thermal_series(self, graph, edges=None) -> np.ndarray:
        """The contact resistance ``R_c / A_ij`` [K/W] in series with each edge's half cells (0
        inside a grain; inf on a contact that carries no force under a pressure law)."""
        rc = self.contact_resistance
        rows = self._lookup(graph, edges)
        if not callable(rc):
            return self._per_area(rows, rc)
        pair = self._made[5][np.maximum(rows, 0)]
        link = (rows >= 0) & (pair[:, 0] >= 0)
        spec = np.zeros(rows.size)
        if np.any(link):
            grains, inv = np.unique(pair[link], axis=0, return_inverse=True)
            force = np.asarray(self.normal_force(grains), float).reshape(-1)
            if force.shape != (grains.shape[0],) or not np.all(np.isfinite(force)) or np.any(force < 0):
                raise BoundaryConditionError(f"normal_force gave {force!r} for the grain pairs {grains.tolist()}: "
                                             "want one finite force >= 0 (N) per pair")
            contacts = self._made[6]
            area = np.array([contacts[(int(i), int(j))] for i, j in grains])
            pressure = force / area
            spec_pair = np.full(grains.shape[0], np.inf)
            for k, p in enumerate(pressure):
                if p > 0:
                    try:
                        spec_pair[k] = contact_resistance_value(rc(float(p)))
                    except BoundaryConditionError as exc:
                        raise BoundaryConditionError(f"contact_resistance({p:.6g} Pa) of grains {tuple(grains[k])}: "
                                                     f"{exc}") from None
            spec[link] = spec_pair[inv.ravel()]
        return self._per_area(rows, spec)

    def film_resistance(self, graph, edges=None) -> np.ndarray:
        """The film's resistance ``film / A_ij`` [ohm] across each contact link (0 elsewhere)."""
        rows = self._lookup(graph, edges)
        return self._per_area(rows, self.film) if self.film else np.zeros(rows.size)

    def cell_volumes(self, graph) -> np.ndarray:
        """Each element's cell volume [m^3] (its template's)."""
        _, nodes = self._nodes(graph)
        volume = np.empty(graph.n_nodes)
        for k, at in enumerate(nodes):
            volume[at] = self.grains.template(k).volume
        return volume
