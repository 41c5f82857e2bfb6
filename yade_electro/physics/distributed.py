"""Conduction, Joule heat and heat on a packing split between MPI ranks (numpy + MPI, no YADE).

Each rank gives, at each call, its share of the packing as a
:class:`~yade_electro.physics.shares.Share`: a contact graph
whose first ``n_owned`` nodes are the elements it owns and the rest the ghosts they touch (other
ranks' elements), with the edges that have an owned end. :class:`DistributedElectroThermal`
then does what :class:`~yade_electro.physics.coupled.ElectroThermalModel` does serially, every
call collective:

* the geometric factors of the law on the share's edges: the contact laws need the pair only;
  the continuum law's transmission surface S_i needs an element's whole neighbourhood, so each
  owner computes it for its own elements and sends it to the ranks that see them as ghosts;
* conductances ``g / rho_edge(T)`` (the mean of the two ends' rho_e(T), ghosts' temperatures
  from their owners) and ``lambda g``;
* the potential with fixed-potential electrodes, branch currents, R_eq, Joule heat per element;
* the heat step by the theta method with fixed temperatures and convection.

The 'voronoi' law's faces need a tessellation, wider than the pairs: its shares are carved by
:func:`~yade_electro.physics.shares.carve_region_share` from the rank's *region* (its own elements and a halo
around them), on which the rank's law object tessellates, once per region; the factors and the
cell volumes (heat capacities, 'cells' Joule sharing) of the owned elements come from there.

Walls of a granular bed (YADE bodies every rank sees: under yade.mpy the master's) join the
spheres touching them to a value held apart from the elements: a wall electrode's potential,
an isothermal wall's temperature. Each rank gives the contacts of its own spheres
(:meth:`DistributedElectroThermal.set_wall_contacts`); a link is a diagonal term and a right-
hand side on its sphere's row, so the walls add no row, no column and no message.

Electrodes fed an imposed current are met by superposition (one solve more per such
electrode, each on the kept setup: :class:`~yade_electro.network.distributed.PartitionedConduction`).

Per-material tables (not done yet) raise :class:`~yade_electro.core.errors.BoundaryConditionError` at setup.

Units: SI (m, ohm m, S, V, A, W, K, J/K, W/K, s).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Dict, Optional, Sequence

import numpy as np

from ..core.errors import BoundaryConditionError
from ..core.materials import Material, electrical_conductance, thermal_conductance_of
from ..laws.factors import edge_lengths, is_contact_law, make_law
from ..laws.transmission import exposed_area, transmission_surface, volume_fraction
from ..network.distributed import PartitionedConduction, PartitionedHeat
from ..solvers.partitioned import GhostExchange, mpi_comm, summed
from .integrator import joule_sharing_for
from .shares import Share

__all__ = ["DistributedElectroThermal", "Held", "Exchange", "IsothermalWall", "Feed", "DISTRIBUTED_LAWS",
           "REGION_LAWS"]

#: the laws a distributed run computes
DISTRIBUTED_LAWS = ("continuum", "contact", "liggghts", "pipe", "voronoi")
#: the laws whose shares are carved from a region with a halo
#: (:func:`~yade_electro.physics.shares.carve_region_share`)
REGION_LAWS = ("voronoi",)


def _per_element(ids, values, message: str):
    """(ids, values) as flat arrays, one finite value >= 0 per body id; else
    BoundaryConditionError(``message``)."""
    ids, v = np.asarray(ids, np.int64).ravel(), np.asarray(values, float).ravel()
    if ids.shape != v.shape or not np.all(np.isfinite(v)) or np.any(v < 0):
        raise BoundaryConditionError(message)
    return ids, v


def _owned(by_id, share: Share):
    """(owned node indices, their values) of ``by_id`` = (body ids, values) (None: none): the
    entries of the ids this rank owns in ``share``."""
    if by_id is None or not share.n_owned or not by_id[0].size:
        return np.zeros(0, np.int64), np.zeros(0)
    ids, v = by_id
    on = np.isin(ids, share.owned_ids)
    return share.graph.index_of(ids[on]), v[on]


@dataclass(frozen=True)
class Held:
    """Elements held at a value: an electrode at ``value`` V or a fixed temperature at ``value``
    K, chosen by ``select`` (body ids, or a callable ``f(pos, radius) -> mask`` evaluated once on
    the first share and then kept by id on every rank). ``wall=True``: an electrode on a wall
    of a granular bed (``select`` unused), joined to the spheres touching it through their
    contacts (given before each call by
    :meth:`DistributedElectroThermal.set_wall_contacts`). ``surface``: an electrode or a
    fixed temperature on a surface of the solid (``select`` unused), joined to the elements
    whose bounded cells have faces on it through their half cells (given once by
    :meth:`DistributedElectroThermal.set_surface`). ``fed=True``: an electrode fed an
    imposed current ``value`` [A] (its potential is found)."""

    name: str
    select: object
    value: float
    wall: bool = False
    fed: bool = False
    surface: object = None

    @property
    def linked(self) -> bool:
        """Held apart from the elements, through links (a wall or a surface)."""
        return self.wall or self.surface is not None


@dataclass(frozen=True)
class Feed:
    """Heat fed into the elements ``select`` chose (None: every element), as
    :class:`~yade_electro.network.heat_conditions.HeatFlux` (``kind='flux'``) or
    :class:`~yade_electro.network.heat_conditions.HeatSource` (``kind='source'``) do serially:
    ``rate`` [W] in total, shared over all ranks in proportion to the weights (a flux: equal
    shares, or its scalar ``area``, or on a ``surface`` its boundary faces' areas; a source: the
    elements' volumes), or ``density`` [W/m^2 or W/m^3] times each weight (a flux: its
    ``area``, None for the exposed area; a source: the volumes). Held elements take none."""

    name: str
    select: object
    kind: str
    rate: Optional[float] = None
    density: Optional[float] = None
    area: Optional[float] = None
    surface: object = None


@dataclass(frozen=True)
class IsothermalWall:
    """A wall of a granular bed held at ``temperature`` [K], joined to the spheres touching it
    through their contacts (the harmonic mean of the particles' conductivity and the wall's
    ``conductivity`` [W/(m K)], None: the particles')."""

    name: str
    temperature: float
    conductivity: Optional[float] = None


@dataclass(frozen=True)
class Exchange:
    """Convection ``h A (t_inf - T)`` on the elements ``select`` chose; ``area`` [m^2] a
    scalar, or None for the exposed area of the continuum model. ``surface``: on a surface
    of the solid (``select`` and ``area`` unused), each element with boundary faces on it by
    the area of its faces in series with its half cell (given once by
    :meth:`DistributedElectroThermal.set_surface`)."""

    name: str
    select: object
    h: float
    t_inf: float
    area: Optional[float] = None
    surface: object = None


class DistributedElectroThermal:
    """See the module doc.

    Parameters
    ----------
    material : Material
        Scalars: resistivity (with electrodes), beta and reference_temperature, density,
        specific_heat and conductivity (with heat).
    law : str
        One of :data:`DISTRIBUTED_LAWS`; ``law_params`` its parameters.
    electrodes : list of Held (potentials [V], or imposed currents [A] with ``fed=True``;
        ``wall=True``: on a wall)
    fixed : list of Held (temperatures [K]); convection : list of Exchange
    walls : list of IsothermalWall (with heat); the contacts of every wall (electrodes' and
        isothermal ones) are given before each call by :meth:`set_wall_contacts`
    feeds : list of Feed (heat fluxes and sources, with heat)
    temperature : float, initial temperature [K]; None: no heat (conduction only)
    theta : the integrator's theta; eta : the share of the Joule power turned into heat;
    joule_sharing : 'auto', 'edges' or 'cells', as ``Integrator(joule_sharing=...)``;
    safety, max_substeps : the explicit sub-steps (see PartitionedHeat)
    volume_fraction : float or None (the continuum model's from the bonds)
    preconditioner : of the partitioned solves ('deflation', 'hypre', 'gamg', 'jacobi')
    comm : mpi4py or petsc4py communicator (default all ranks)
    """

    def __init__(self, material: Material, law: str = "continuum", law_params: Optional[dict] = None, *,
                 electrodes: Sequence[Held] = (), fixed: Sequence[Held] = (), convection: Sequence[Exchange] = (),
                 walls: Sequence[IsothermalWall] = (), feeds: Sequence[Feed] = (),
                 temperature: Optional[float] = None, theta="backward-euler", eta: float = 1.0, joule_sharing="auto",
                 volume_fraction: Optional[float] = None, safety: float = 0.9, max_substeps: int = 100000,
                 preconditioner: str = "deflation", rtol: float = 1e-10, comm=None):
        if law not in DISTRIBUTED_LAWS:
            raise BoundaryConditionError(f"a distributed run computes the laws {', '.join(DISTRIBUTED_LAWS)}; law "
                                         f"{law!r} is not one of them")
        if law in REGION_LAWS:
            for item in convection:
                if item.area is None and item.surface is None:
                    raise BoundaryConditionError(
                        f"convection {item.name!r} with the {law!r} law needs a scalar area= [m^2] in a distributed "
                        "run (the exposed area there is the continuum model's)")
        self.material, self.law_name = material, law
        self.law = make_law(law, **dict(law_params or {}))
        self.walls = list(walls) if temperature is not None else []
        self.feeds = list(feeds) if temperature is not None else []
        self._fed = None                          # the feeds' power [W] per owned node
        self._read_graph = None                   # the last share's graph as read (before the contacts' filter)
        self.flux_energy = 0.0
        if self.walls or any(e.wall for e in electrodes):
            try:
                self.law.wall_factor(np.ones(1), np.zeros(1))
            except ValueError as exc:
                raise BoundaryConditionError(f"walls with law {law!r}: {exc}") from None
        self._contacts: Dict[str, tuple] = {}
        self._surfaces: Dict[str, tuple] = {}    # name -> (ids, g [m] or area [m^2]) on a surface
        self.electrodes, self.fixed, self.convection = list(electrodes), list(fixed), list(convection)
        self.temperature0 = temperature
        self.theta, self.eta, self.volume_fraction = theta, float(eta), volume_fraction
        self.joule_sharing = joule_sharing_for(joule_sharing, law)
        self.safety, self.max_substeps = float(safety), int(max_substeps)
        self.preconditioner, self.rtol = preconditioner, float(rtol)
        # the deflation's smoother, by system (bench/bench_peers.py, partitioned lines): ICC
        # halves the iterations on contact and continuum networks (35-41 against 90-92 at 1M
        # unknowns) and is the faster; on Voronoi networks (more neighbours, spread
        # conductances) it saves a third of them and costs more than it saves: Jacobi there
        self.smoother = "jacobi" if law in REGION_LAWS else "icc"
        self.comm = mpi_comm(comm)
        self._ids: Dict[str, np.ndarray] = {}
        self._T_kept = None              # (sorted ids, their temperatures) of the last share
        self.share: Optional[Share] = None
        self.conduction: Optional[PartitionedConduction] = None
        self.heat: Optional[PartitionedHeat] = None
        self.time = 0.0
        self.joule_energy = 0.0

    # -- the share and its values ------------------------------------------------------------
    @property
    def surface_names(self) -> dict:
        """name -> surface of the electrodes, fixed temperatures and convections on a surface,
        whose elements :meth:`set_surface` gives."""
        items = list(self.electrodes) + list(self.fixed) + list(self.convection) + list(self.feeds)
        return {e.name: e.surface for e in items if e.surface is not None}

    def set_surface(self, name: str, ids, values):
        """The elements (body ids; those this rank does not own are ignored) of the surface
        condition ``name``, kept for the run, with per element: an electrode's or a fixed
        temperature's half-cell factor g [m] (a half cell conducts ``g / rho_e`` or
        ``lambda g``), a convection's area [m^2] (its faces in series with the half cell), a
        heat flux's faces' area [m^2]."""
        if name not in self.surface_names:
            raise BoundaryConditionError(f"no surface condition named {name!r}; have {sorted(self.surface_names)}")
        self._surfaces[name] = _per_element(ids, values, f"{name!r}: values must be finite and >= 0, one per element")

    def _surface_values(self, name: str, share: Share) -> np.ndarray:
        """The values :meth:`set_surface` gave on each owned node (0 elsewhere)."""
        g = np.zeros(share.n_owned)
        nodes, v = _owned(self._surfaces.get(name), share)
        g[nodes] = v
        return g

    @property
    def wall_names(self) -> list:
        """The walls whose contacts :meth:`set_wall_contacts` takes: the electrodes' and the
        isothermal ones."""
        return [e.name for e in self.electrodes if e.wall] + [w.name for w in self.walls]

    def set_wall_contacts(self, name: str, ids, overlap):
        """The spheres (body ids; those this rank does not own are ignored) touching wall
        ``name`` now and their overlaps [m] (> 0), for the next call."""
        if name not in self.wall_names:
            raise BoundaryConditionError(f"no wall named {name!r}; have {self.wall_names}")
        self._contacts[name] = _per_element(ids, overlap,
                                            f"wall {name!r}: overlaps must be finite and >= 0 (m), one per sphere")

    def _wall_factor(self, name: str, share: Share) -> np.ndarray:
        """Geometric factor g [m] of each owned node's link to wall or surface ``name`` (0:
        none): a wall's contact, a surface's half cell."""
        if name in self.surface_names:
            return self._surface_values(name, share)
        g = np.zeros(share.n_owned)
        nodes, dl = _owned(self._contacts.get(name), share)
        if nodes.size:
            g[nodes] = self.law.wall_factor(share.graph.radius[nodes], dl)
        return g

    def _electrode_links(self, share: Share, T_owned) -> Optional[np.ndarray]:
        """(electrodes, owned nodes) conductances [S] of the wall electrodes' contacts and the
        surface electrodes' half cells, the element's rho_e(T); None when no electrode is on a
        wall or a surface."""
        if not any(e.linked for e in self.electrodes):
            return None
        n, m = share.n_owned, self.material
        rho = m.resistivity_at(None if m.beta == 0.0 else np.asarray(T_owned, float))
        links = np.zeros((len(self.electrodes), n))
        for k, e in enumerate(self.electrodes):
            if e.linked:
                links[k] = self._wall_factor(e.name, share) / rho
        return links

    def _heat_links(self, share: Share):
        """Give the heat solver each isothermal wall's contact conductances and each surface
        fixed temperature's half-cell conductances [W/K]."""
        lam = float(self.material.conductivity) if self.heat.link_names else 0.0
        for w in self.walls:
            lam_w = lam if w.conductivity is None else float(w.conductivity)
            self.heat.set_links(w.name, 2.0 * lam * lam_w / (lam + lam_w) * self._wall_factor(w.name, share))
        for item in self.fixed:
            if item.surface is not None:
                self.heat.set_links(item.name, lam * self._wall_factor(item.name, share))

    def _chosen(self, item, share: Share) -> np.ndarray:
        """Mask of the owned nodes ``item`` holds (its ids fixed on the first share, all ranks)."""
        if getattr(item, "linked", False):
            return np.zeros(share.n_owned, bool)
        if getattr(item, "surface", None) is not None:          # a convection or a flux on a surface
            return self._surface_values(item.name, share) > 0
        if item.select is None:                                # a source on every element
            return np.ones(share.n_owned, bool)
        if item.name not in self._ids:
            mine = np.zeros(0, np.int64)
            if share.graph is not None:
                n = share.n_owned
                if callable(item.select):
                    mask = np.asarray(item.select(share.graph.pos[:n], share.graph.radius[:n]), dtype=bool)
                    mine = share.owned_ids[mask]
                else:
                    mine = share.owned_ids[np.isin(share.owned_ids, np.asarray(item.select, np.int64))]
            ids = np.unique(np.concatenate(self.comm.allgather(mine)))
            if ids.size == 0:
                raise BoundaryConditionError(f"{item.name!r} selects no element on any rank: check its region/ids "
                                             "against the packing (selection is by element centre)")
            self._ids[item.name] = ids
        return np.isin(share.owned_ids, self._ids[item.name])

    def _factor(self, share: Share, exchange: GhostExchange) -> np.ndarray:
        g = share.graph
        if g is None:
            return np.zeros(0)
        if is_contact_law(self.law_name):
            return self.law.factor(g, g.edges)
        if self.law_name in REGION_LAWS:
            raise ValueError(f"the {self.law_name!r} law's shares are carved with carve_region_share (they carry "
                             "their factors)")
        S = transmission_surface(g, threshold=self.law.threshold, factor=self.law.factor_)
        S = exchange.local(S[:share.n_owned])
        return np.sqrt(S[g.edges[:, 0]] * S[g.edges[:, 1]]) / edge_lengths(g, g.edges)

    def _volume(self, share: Share) -> np.ndarray:
        """The volume each owned element stands for [m^3] (its heat capacity over rho c)."""
        g, n = share.graph, share.n_owned
        if g is None:
            return np.zeros(0)
        if share.volume is not None and self.volume_fraction is None:     # cells that fill the solid
            return share.volume
        fv = volume_fraction(g)[:n] if self.volume_fraction is None else self.volume_fraction
        return g.volume[:n] / fv

    def _cell_sources(self, share: Share, power) -> np.ndarray:
        """The owned elements' Joule heat [W] by :func:`.thermal.cell_joule_sources`, the total
        kept over the ranks (collective: a rank that owns nothing joins the sums)."""
        from .thermal import cell_joule_sources
        if share.graph is None:
            summed(self.comm, np.zeros(2))
            return power
        m, c = self.material, self.conduction
        rho = m.resistivity_at(None if m.beta == 0.0 else np.asarray(self.T, float))
        edges = c.network.edges[np.asarray(c.conductance) > 0]
        return cell_joule_sources(share.graph.pos, edges, c.potential, self._volume(share), rho, power,
                                  owned=share.n_owned, reduce=lambda v: summed(self.comm, v), held=c.held)

    def _conductance(self, T_owned) -> np.ndarray:
        """Electrical conductances [S] of the share's edges at the owned temperatures [K]
        (rho_e(T) of the ghosts from their owners)."""
        m = self.material
        rho = m.resistivity_at(None if m.beta == 0.0 else np.asarray(T_owned, float))
        if np.ndim(rho):
            rho = self._exchange.local(rho)
        return electrical_conductance(self.factor, rho, self.share.network.edges)

    def _thermal(self) -> np.ndarray:
        """Thermal conductances [W/K] of the share's edges."""
        return thermal_conductance_of(self.factor, self.material.conductivity, self.share.network.edges)

    def prepare(self, share: Share, factor=None):
        """Set up the solves on a new share (new element set or edges), carrying the temperatures
        of the elements kept (by id); ``factor``: the share's geometric factors when the caller
        has them."""
        self.share = share
        old_heat = dict(self.heat.link_energy) if self.heat is not None else None
        for old in (self.conduction, self.heat):     # every rank prepares: free the old solvers together
            if old is not None:
                old.close()
        self.conduction = self.heat = None
        net = share.network
        exchange = GhostExchange(net, self.comm)
        self._exchange = exchange
        self.factor = self._factor(share, exchange) if factor is None else factor
        n = share.n_owned
        pos = share.graph.pos[:n] if share.graph is not None else np.zeros((0, 3))
        spacing = self._spacing(share)
        self.T = T = self._temperatures(share)
        self._pos, self._spacing_now = pos, spacing
        if self.electrodes:
            self._new_conduction(share, T)
        if self.temperature0 is not None:
            fixed = np.full(n, np.nan)
            for item in self.fixed:
                fixed[self._chosen(item, share)] = item.value
            hA, t_inf = np.zeros(n), np.zeros(n)
            for item in self.convection:
                on = self._chosen(item, share)
                area = self._convection_area(item, share, on)
                t_inf[on] = (t_inf[on] * hA[on] + item.h * area[on] * item.t_inf) / np.maximum(
                    hA[on] + item.h * area[on], 1e-300)
                hA[on] += item.h * area[on]
            rho_c = self.material.density * self.material.specific_heat
            self.heat = PartitionedHeat(net, rho_c * self._volume(share), self._thermal(), T,
                                        fixed=fixed, h_area=hA, t_inf=t_inf, theta=self.theta, comm=self.comm,
                                        preconditioner=self.preconditioner, rtol=1e-12, pos=pos, spacing=spacing,
                                        safety=self.safety, max_substeps=self.max_substeps, smoother=self.smoother,
                                        links={**{w.name: w.temperature for w in self.walls},
                                               **{f.name: f.value for f in self.fixed if f.surface is not None}})
            self._fed = self._feed_power(share, fixed)
            if old_heat is not None:            # the walls' heat goes on
                for k, v in old_heat.items():
                    self.heat.link_energy[k] = v
            self.T = self.heat.T

    def _feed_power(self, share: Share, fixed) -> np.ndarray:
        """The feeds' power [W] on each owned node, held ones excluded (collective)."""
        n = share.n_owned
        q = np.zeros(n)
        for f in self.feeds:
            on = self._chosen(f, share)
            if f.kind == "source":
                w = self._volume(share) if n else np.zeros(0)
            elif f.surface is not None:
                w = self._surface_values(f.name, share)
            elif f.rate is not None or f.area is not None:
                w = np.full(n, 1.0 if f.area is None else float(f.area))
            else:
                w = self._exposed_area(share)
            if f.rate is not None:
                total = float(summed(self.comm, np.array([w[on].sum() if n else 0.0]))[0])
                if not total > 0:
                    raise BoundaryConditionError(f"{f.name!r}: its elements' {'volumes' if f.kind == 'source' else 'areas'} "
                                                 "sum to 0 over the ranks")
                q[on] += f.rate * w[on] / total
            else:
                q[on] += f.density * w[on]
        q[~np.isnan(fixed)] = 0.0
        return q

    def _convection_area(self, item: Exchange, share: Share, on) -> np.ndarray:
        """The area [m^2] of convection ``item`` on each owned node (used where ``on``)."""
        n = share.n_owned
        if share.graph is None:
            return np.zeros(0)
        if item.surface is not None:
            return self._surface_values(item.name, share)
        if item.area is None:
            return self._exposed_area(share)
        return np.full(n, float(item.area))

    def _exposed_area(self, share: Share) -> np.ndarray:
        """The default exposed area [m^2] of each owned node, from the graph as read (a bed's
        Verlet pairs, touching or not, as the serial model takes it), not from the contacts
        that conduct: both runs then agree."""
        g = self._read_graph
        if g is None or g.n_nodes != (share.graph.n_nodes if share.graph is not None else 0):
            g = share.graph
        return exposed_area(g)[:share.n_owned] if share.n_owned else np.zeros(0)

    def _new_conduction(self, share: Share, T):
        """The conduction solve on ``share`` with the wall electrodes' contacts now (collective)."""
        if self.conduction is not None:
            self.conduction.close()
        el = np.full(share.n_owned, -1, np.int64)
        for k, item in enumerate(self.electrodes):
            el[self._chosen(item, share)] = k
        self.conduction = PartitionedConduction(
            share.network, self._conductance(T), el, [e.name for e in self.electrodes], self._potentials(),
            comm=self.comm, preconditioner=self.preconditioner, rtol=self.rtol, pos=self._pos,
            spacing=self._spacing_now, smoother=self.smoother, links=self._electrode_links(share, T),
            currents=self._currents())

    def _potentials(self) -> list:
        """The electrodes' potentials [V] (0 for those fed a current: found by the solve)."""
        return [0.0 if e.fed else e.value for e in self.electrodes]

    def _currents(self) -> list:
        """The electrodes' imposed currents [A] (None for those held at a potential)."""
        return [e.value if e.fed else None for e in self.electrodes]

    def _spacing(self, share: Share) -> float:
        """Mean edge length over all ranks [m] (the deflation's cluster unit)."""
        g = share.graph
        local = edge_lengths(g, g.edges) if g is not None and g.n_edges else np.zeros(0)
        s = summed(self.comm, np.array([local.sum(), float(local.size)]))
        return float(s[0] / s[1]) if s[1] > 0 else 1.0

    def _temperatures(self, share: Share) -> np.ndarray:
        n = share.n_owned
        T0 = float(self.temperature0) if self.temperature0 is not None else float(
            self.material.reference_temperature or 0.0)
        T = np.full(n, T0)
        if self._T_kept is not None and n:               # the elements kept take their temperature
            ids, temps = self._T_kept
            at = np.minimum(np.searchsorted(ids, share.owned_ids), max(ids.size - 1, 0))
            kept = ids[at] == share.owned_ids if ids.size else np.zeros(n, bool)
            T[kept] = temps[at[kept]]
        return T

    # -- one call ----------------------------------------------------------------------------
    def step(self, share: Share, dt: Optional[float]) -> dict:
        """One call on ``share`` (a new element set or edge set rebuilds the solves, else the
        values are refreshed in place): the potential, the Joule heat, and a heat step of
        ``dt`` [s] (None or 0: no heat step). Returns the totals of all ranks."""
        factor = share.factor
        self._read_graph = share.graph           # its edges: the default exposed areas' (as serially)
        if is_contact_law(self.law_name) and share.graph is not None:   # pair factors: once, on all contacts
            factor = self.law.factor(share.graph, share.graph.edges)
            touching = factor > 0
            share, factor = share.conducting(touching), factor[touching]
        old = self.share
        changed = (old is None or share.network.edges.shape != old.network.edges.shape
                   or not np.array_equal(share.network.owned_key, old.network.owned_key)
                   or not np.array_equal(share.network.ghost_key, old.network.ghost_key)
                   or not np.array_equal(share.network.edges, old.network.edges))
        if self.comm.allreduce(int(changed)):        # one rank's new structure is everyone's new setup
            if old is not None:
                order = np.argsort(old.owned_ids)
                self._T_kept = (old.owned_ids[order], self.T[order])
            self.prepare(share, factor)
        else:
            self.share = share
            self.factor = self._factor(share, self._exchange) if factor is None else factor
            if self.heat is not None:
                self.heat.update_conductance(self._thermal())
        power = np.zeros(share.n_owned)
        row: Dict[str, float] = {}
        if self.conduction is not None:
            links = self._electrode_links(share, self.T)
            if links is not None and self.comm.allreduce(int(not self.conduction.links_fit(links))):
                self._new_conduction(share, self.T)       # spheres came to or left a wall electrode
            self.conduction.update_conductance(self._conductance(self.T), links)
            self.conduction.solve(self._potentials(), self._currents())
            power = self.eta * self.conduction.joule_power()
            if self.joule_sharing == "cells" and self.temperature0 is not None:   # the volumes: from the heat data
                power = self._cell_sources(share, power)
            currents = self.conduction.electrode_currents()
            row["R_eq"] = self.conduction.equivalent_resistance() if len(self.electrodes) >= 2 else math.inf
            volts = self.conduction.electrode_potentials()
            names = [e.name for e in self.electrodes]
            # the serial engines' names: the first electrode's current, the voltage between the first two
            row["current"] = currents[names[0]]
            row["voltage"] = volts[names[0]] - (volts[names[1]] if len(names) > 1 else 0.0)
            row.update({f"V_{k}": v for k, v in volts.items()})
            row.update({f"I_{k}": v for k, v in currents.items()})
            row["joule_power"] = float(summed(self.comm, np.array([power.sum()]))[0])
            row["solve_iterations"] = int(self.conduction.info["iterations"])
        if self.heat is not None:
            self._heat_links(share)
        if self.heat is not None and dt:
            if self._fed is not None and self.feeds:
                power = power + self._fed
                self.flux_energy += float(summed(self.comm, np.array([self._fed.sum()]))[0]) * dt
            self.T = self.heat.advance(dt, power)
            row["n_substeps"] = int(self.heat.substeps)
            self.time += dt
            self.joule_energy += row.get("joule_power", 0.0) * dt
        if self.heat is not None:
            from mpi4py import MPI
            n_all = self.comm.allreduce(int(self.T.size))
            row["T_mean"] = float(summed(self.comm, np.array([self.T.sum()]))[0] / max(n_all, 1))
            row["T_max"] = self.comm.allreduce(float(self.T.max()) if self.T.size else -np.inf, op=MPI.MAX)
            row["heat_content"] = self.heat.heat_content(float(self.material.reference_temperature or 0.0))
            if self.feeds:
                row["flux_heat"] = self.flux_energy
            flows = self.heat.link_flows()
            for w in self.walls:
                ids = self._contacts.get(w.name, (np.zeros(0, np.int64),))[0]
                row[f"wall_contacts:{w.name}"] = int(self.comm.allreduce(int(np.count_nonzero(
                    np.isin(ids, share.owned_ids)))))
                row[f"wall_power:{w.name}"] = flows[w.name]
                row[f"wall_heat:{w.name}"] = self.heat.link_energy[w.name]
        row["elements"] = int(self.comm.allreduce(int(share.n_owned)))
        return row

    def set_electrode(self, name: str, value: float):
        """A new potential [V] (or imposed current [A], for an electrode fed one) for electrode
        ``name`` from the next call on (every rank)."""
        names = [e.name for e in self.electrodes]
        if name not in names:
            raise BoundaryConditionError(f"no electrode named {name!r}; have {names}")
        k = names.index(name)
        self.electrodes[k] = dataclasses.replace(self.electrodes[k], value=float(value))

    @property
    def potential(self) -> np.ndarray:
        """Potential [V] of the owned elements (``share.owned_ids`` order)."""
        if self.conduction is None:
            return np.zeros(self.share.n_owned if self.share else 0)
        return self.conduction.potential[:self.share.n_owned]

    def temperatures_by_id(self) -> Dict[int, float]:
        return dict(zip(self.share.owned_ids.tolist(), self.T.tolist()))
