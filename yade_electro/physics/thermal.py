"""The thermal physics layer: heat capacities, thermal conductances and Joule sources.

The lumped heat balance of a packing (paper 000 eq. 13 and 16, paper 003 eq. 14):

    C_i dT_i/dt = P_i + sum_j G_ij (T_j - T_i) + h_i A_i (T_inf,i - T_i) + Q_i

* ``C_i = rho c V_i / fv_i`` [J/K], the heat capacity of the volume the element stands for
  (:func:`heat_capacity`);
* ``P_i`` [W], half the Joule power ``eta w_ij^2 / c_ij`` of every bond of i
  (:func:`joule_sources`);
* ``G_ij = lambda S_ij / l_ij`` [W/K], the thermal conductance; any electrical conductance
  law gives it when called with the thermal resistivity 1/lambda
  (:func:`thermal_conductance`; the 'continuum' law gives exactly paper 000 eq. 16);
* convection ``h A (T_inf - T)`` on free-surface elements and imposed heat inputs ``Q_i``
  [W]; fixed-temperature node sets take the place of electrodes.

The network integrates it in time (:mod:`yade_electro.network.transient`, with the explicit
stability bound) or solves its steady state.

Units: SI (kg/m^3, J/(kg K), W/(m K), W/(m^2 K), K or degC, J/K, W, s).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Optional

import numpy as np

from ..core.errors import BoundaryConditionError, MaterialError
from ..core.graph import ContactGraph
from ..core.materials import Material, positive_property, thermal_conductance_of
from ..laws.factors import make_law
from ..laws.transmission import volume_fraction as _volume_fraction
from ..network.boundary import Condition
from ..network.heat_conditions import ThermalWall
from ..network.kirchhoff import edge_power
from ..network.transient import HeatSolver

__all__ = ["heat_capacity", "thermal_conductance", "diffusion_time_step", "edge_joule_power", "joule_sources", "cell_joule_sources",
           "electrical_power", "heat_solver_on_graph", "heat_material", "split_heat_boundaries", "surface_conditions",
           "source_power"]


# ---------------------------------------------------------------------------------------
# material input
# ---------------------------------------------------------------------------------------
def heat_capacity(graph: ContactGraph, density, specific_heat, volume_fraction=None, cell_volume=None,
                  threshold: float = 0.4, factor: float = 2.0) -> np.ndarray:
    """Heat capacity C_i of every element [J/K].

    ``C_i = rho c V_i / fv_i`` (paper 000 eq. 13), V_i the sphere volume and fv_i the volume
    fraction of the continuum model (:func:`yade_electro.laws.transmission.volume_fraction`), so that
    the element carries the heat capacity of the polyhedron it stands for.

    Parameters
    ----------
    graph : ContactGraph
    density : float or (n,) [kg/m^3], > 0
    specific_heat : float or (n,) [J/(kg K)], > 0
    volume_fraction : float or (n,), optional
        Explicit fv_i (e.g. 1.0 for the paper's rod check); default from the bond graph.
    cell_volume : (n,) array [m^3], optional
        Volumes of the cells the elements stand for (e.g. Voronoi cells); then
        ``C_i = rho c V_cell_i`` and ``volume_fraction`` must not be given.
    threshold, factor : eccentricity rule of the default volume fraction.

    Raises
    ------
    MaterialError
        A non-positive or non-finite density, specific heat, volume fraction or cell volume.
    """
    n = graph.n_nodes
    rc = positive_property("density", density, n, " (kg/m^3)") * positive_property("specific_heat", specific_heat, n,
                                                                      " (J/(kg K))")
    if cell_volume is not None:
        if volume_fraction is not None:
            raise ValueError("give volume_fraction= or cell_volume=, not both")
        v = positive_property("cell_volume", cell_volume, n, " (m^3)")
        return np.broadcast_to(rc * v, (n,)).astype(float)
    if volume_fraction is None:
        fv = _volume_fraction(graph, threshold=threshold, factor=factor)
    else:
        fv = positive_property("volume_fraction", volume_fraction, n)
    return np.broadcast_to(rc * graph.volume / fv, (n,)).astype(float)


def thermal_conductance(graph: ContactGraph, conductivity, law="continuum", **params) -> np.ndarray:
    """Thermal conductance G_ij of every edge of ``graph`` [W/K]: ``lambda_edge g`` with the
    law's geometric factor g (for 'continuum', ``lambda S_ij / l_ij``, paper 000 eq. 16);
    per-node conductivities make an edge two half rods in series (harmonic mean).

    Raises
    ------
    MaterialError
        A non-positive or non-finite conductivity [W/(m K)].
    """
    lam = positive_property("thermal conductivity", conductivity, graph.n_nodes, " (W/(m K))")
    return thermal_conductance_of(make_law(law, **params).factor(graph, graph.edges), lam, graph.edges)


def diffusion_time_step(graph: ContactGraph, conductivity, density, specific_heat) -> float:
    """Paper 000 eq. 14: ``l_min^2 / (2 alpha)`` [s], alpha = lambda / (rho c) (the largest
    over the nodes when properties vary). For comparison with :func:`stable_time_step`,
    which is the bound the integrators use."""
    n = graph.n_nodes
    alpha = (positive_property("thermal conductivity", conductivity, n) /
             (positive_property("density", density, n) * positive_property("specific_heat", specific_heat, n)))
    if graph.n_edges == 0:
        return math.inf
    return float(np.min(graph.length) ** 2 / (2.0 * np.max(alpha)))


# ---------------------------------------------------------------------------------------
# Joule heating
# ---------------------------------------------------------------------------------------
def edge_joule_power(branch_current, conductance, eta: float = 1.0) -> np.ndarray:
    """Heat released in every edge, ``eta u_ij w_ij = eta w_ij^2 / c_ij`` [W] (paper 000
    eq. 11); 0 on edges of zero conductance (they carry no current)."""
    if not (0.0 <= eta <= 1.0):
        raise ValueError(f"eta (share of the electrical power released as heat) must be in [0, 1], got {eta}")
    w = np.asarray(branch_current, dtype=float)
    c = np.asarray(conductance, dtype=float)
    if w.shape != c.shape or w.ndim != 1:
        raise ValueError(f"branch_current and conductance must be (m,) arrays of one shape, got {w.shape} "
                         f"and {c.shape}")
    return eta * edge_power(w, c)


def joule_sources(edges, branch_current, conductance, n_nodes: int, eta: float = 1.0) -> np.ndarray:
    """Joule power received by every node [W]: each edge's ``eta w^2 / c`` shared half and half
    by its two end nodes. The total equals ``eta * sum_e V_e I_e`` over the electrodes
    (:func:`electrical_power`) when no current is injected elsewhere."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    p = edge_joule_power(branch_current, conductance, eta)
    if p.shape[0] != edges.shape[0]:
        raise ValueError(f"one branch current per edge expected ({edges.shape[0]}), got {p.shape[0]}")
    return 0.5 * (np.bincount(edges[:, 0], p, n_nodes) + np.bincount(edges[:, 1], p, n_nodes))


def cell_joule_sources(pos, edges, potential, volume, resistivity, edge_sources, owned=None, reduce=None,
                       held=None) -> np.ndarray:
    """Joule power per element [W] from the field over its cell: ``V_i |g_i|^2 / rho_i``, with
    ``g_i`` [V/m] the least-squares gradient of the node ``potential`` [V] over the element's
    neighbours along ``edges`` (weights 1 / l^2; exact for a uniform field), ``volume`` [m^3]
    and ``resistivity`` [ohm m] per element, then scaled so the total is that of
    ``edge_sources`` [W] (the network's power, e.g. :func:`joule_sources`). An element whose
    neighbours do not span three dimensions (fewer than three directions) keeps its value of
    ``edge_sources``, and so do the elements ``held`` (a boolean mask over the nodes of
    ``pos``) and their neighbours along ``edges``. A held element is an electrode's own, its
    potential imposed: the field fills only the part of its cell that faces the solid, which
    is the part the half of each link's heat that 'edges' gives it stands for. Its neighbours'
    stencils hold the field's kink at the imposed potential, which a linear fit does not
    follow (it gave the first free layer of a rod 1.3 % of its slab's power too much, taken
    from the rest). The rest are scaled to what remains. Elements with no power in
    ``edge_sources`` (floating parts) get none.

    A distributed rank: ``owned``, the number of its elements (the first rows of ``pos`` and
    ``potential``; the rest are ghosts, whose potentials the gradients use); ``volume``,
    ``resistivity`` and ``edge_sources`` are then the owned elements' (``held`` covers the
    ghosts too), and ``reduce`` maps the rank's two sums (the kept edge power, the cells'
    power) to the sums over every rank."""
    pos = np.asarray(pos, float)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    n = pos.shape[0]
    r = n if owned is None else int(owned)
    u = np.asarray(potential, float)[:n]
    p_edge = np.asarray(edge_sources, float)
    d = pos[e[:, 1]] - pos[e[:, 0]]
    wd = d / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)[:, None]       # weights 1 / l^2
    du = u[e[:, 1]] - u[e[:, 0]]

    def at_ends(values):
        """Per element, the sum of ``values`` over its edges (both ends: d and du change sign
        together); the ghosts' rows (distributed) dropped."""
        return (np.bincount(e[:, 0], values, n) + np.bincount(e[:, 1], values, n))[:r]

    m00, m01, m02, m11, m12, m22 = (at_ends(wd[:, a] * d[:, c]) for a, c in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2),
                                                                            (2, 2)))
    # M = sum w d d^T (symmetric) solved by its cofactors: g = adj(M) b / det(M)
    c00, c01, c02 = m11 * m22 - m12 * m12, m02 * m12 - m01 * m22, m01 * m12 - m02 * m11
    c11, c12, c22 = m00 * m22 - m02 * m02, m01 * m02 - m00 * m12, m00 * m11 - m01 * m01
    det = m00 * c00 + m01 * c01 + m02 * c02
    # three directions: the smallest eigenvalue above 1e-6 of the largest (the weights make M
    # dimensionless); det > 1e-6 trace^3 implies it, eigenvalues only for the others
    ok = det > 1e-6 * (m00 + m11 + m22) ** 3
    unsure = np.flatnonzero(~ok)
    if unsure.size:
        M = np.stack([m00, m01, m02, m01, m11, m12, m02, m12, m22], axis=1)[unsure].reshape(-1, 3, 3)
        eig = np.linalg.eigvalsh(M)            # ascending
        ok[unsure] = eig[:, 0] > 1e-6 * np.maximum(eig[:, 2], 1e-300)
    ok &= p_edge > 0
    if held is not None:                       # held elements and their neighbours keep theirs
        h = np.asarray(held, bool)
        ok &= ~(h[:r] | (at_ends(h[e].any(axis=1).astype(float)) > 0))
    b0, b1, b2 = (at_ends(wd[:, a] * du) for a in range(3))
    g = np.column_stack([c00 * b0 + c01 * b1 + c02 * b2, c01 * b0 + c11 * b1 + c12 * b2,
                         c02 * b0 + c12 * b1 + c22 * b2]) / np.where(ok, det, 1.0)[:, None]
    rho = np.broadcast_to(np.asarray(resistivity, float), (r,))
    p = np.where(ok, np.asarray(volume, float) * np.einsum("ij,ij->i", g, g) / rho, 0.0)   # g of the others unused
    sums = np.array([p_edge[ok].sum(), p.sum()])
    rest, total = (sums if reduce is None else np.asarray(reduce(sums), float)).tolist()
    out = p_edge.copy()
    out[ok] = p[ok] * (rest / total) if total > 0 else p_edge[ok]
    return out


def electrical_power(solution) -> float:
    """``sum_e V_e I_e`` over the electrodes of a PotentialSolution [W]: the power the external
    circuit delivers (Tellegen: equals the total Joule power of the network)."""
    return float(sum(solution.electrode_potential[k] * solution.electrode_current[k]
                     for k in solution.electrode_current))


# ---------------------------------------------------------------------------------------
# a heat solver on a graph
# ---------------------------------------------------------------------------------------
def heat_solver_on_graph(graph: ContactGraph, density, specific_heat, conductivity, temperature, *,
                         law="continuum", law_params: Optional[dict] = None, volume_fraction=None,
                         cell_volume=None, **kw) -> HeatSolver:
    """A :class:`~yade_electro.network.transient.HeatSolver` on ``graph``: capacities by
    :func:`heat_capacity`, conductances by :func:`thermal_conductance` with ``law``; other
    keywords go to the solver's constructor (boundary conditions may then use selectors)."""
    C = heat_capacity(graph, density, specific_heat, volume_fraction=volume_fraction, cell_volume=cell_volume)
    G = thermal_conductance(graph, conductivity, law, **(law_params or {}))
    kw.setdefault("coords", graph.pos)
    return HeatSolver(C, graph.edges, G, temperature, graph=graph, **kw)


# ---------------------------------------------------------------------------------------
# the heat model's material and boundaries
# ---------------------------------------------------------------------------------------
def heat_material(material: Material, electrical: Optional[Material], temperature: float) -> Material:
    """The heat model's own ``material`` checked: density, specific heat and conductivity
    given; ``beta`` only with an electrical model; no resistivity other than the electrical
    model's (``electrical``, the one place rho_0 is held: the result leaves it out);
    ``reference_temperature`` defaulting to ``temperature`` [K]. MaterialError otherwise."""
    rho0 = electrical.resistivity if electrical is not None else None
    if material.resistivity is not None and (rho0 is None or not np.array_equal(np.asarray(material.resistivity),
                                                                               np.asarray(rho0))):
        raise MaterialError("the resistivity belongs to the electrical model (ElectricalModel(Material("
                            "resistivity=...), ...)); leave it out of the heat model's material")
    if material.beta != 0.0 and electrical is None:
        raise MaterialError("beta (rho_e(T)) needs an electrical model")
    for name in ("density", "specific_heat", "conductivity"):
        if getattr(material, name) is None:
            raise MaterialError(f"the heat model needs Material(density=..., specific_heat=..., conductivity=...) "
                                f"(kg/m^3, J/(kg K), W/(m K)); {name} is missing")
    T0 = temperature if material.reference_temperature is None else material.reference_temperature
    return dataclasses.replace(material, resistivity=None, reference_temperature=T0)


def split_heat_boundaries(boundaries) -> tuple:
    """``(conditions, sources, walls)`` of a heat model's one list of boundaries: fixed values,
    injections and Robin terms; sources; the ``ThermalWall`` objects. TypeError for anything else,
    BoundaryConditionError for a name given twice."""
    conditions, sources, walls = [], [], []
    for bc in boundaries:
        if isinstance(bc, ThermalWall):
            walls.append(bc)
        elif isinstance(bc, Condition) and bc.ROLE in ("fixed", "injection", "robin"):
            conditions.append(bc)
        elif isinstance(bc, Condition) and bc.ROLE == "source":
            sources.append(bc)
        else:
            raise TypeError(f"boundaries= takes FixedTemperature, HeatFlux, Convection, HeatSource and "
                            f"ThermalWall objects (or FixedValue, Injection, Robin, Source), got {bc!r}")
    names = [b.name for b in conditions + sources + walls]
    if len(set(names)) != len(names):
        raise BoundaryConditionError(f"thermal boundary condition, heat source and wall names must be unique, got "
                                     f"{names}")
    return conditions, sources, walls


# ---------------------------------------------------------------------------------------
# conditions on surfaces, heat sources
# ---------------------------------------------------------------------------------------
def surface_conditions(conditions, contacts: dict, conductivity):
    """The node sets, areas and link conductances of the thermal conditions given on a surface.

    Parameters
    ----------
    conditions : sequence of fixed values, injections and Robin conditions
        (``FixedTemperature``, ``HeatFlux``, ``Convection``); those with no ``surface`` are
        skipped
    contacts : dict name -> :class:`~yade_electro.geometry.boundary.SurfaceContact`
        of each surface condition on the current graph
    conductivity : float or (n,) [W/(m K)]

    Returns
    -------
    nodes_of, area_of, link_of : dicts name -> node indices; areas [m^2] (a flux's boundary
        faces, a convection's area in series with the half cells); conductances [W/K] of a
        fixed temperature held at the surface (``lambda sum_f A_f / d_f`` per node)
    """
    lam = np.asarray(conductivity, dtype=float)
    nodes_of, area_of, link_of = {}, {}, {}
    for b in conditions:
        if b.surface is None:
            continue
        contact = contacts[b.name]
        nodes_of[b.name] = contact.nodes
        if b.ROLE == "fixed":
            link_of[b.name] = (lam if lam.ndim == 0 else lam[contact.nodes]) * contact.factor
        elif b.ROLE == "robin":
            area_of[b.name] = contact.convection_area(b.field("coefficient"), lam)
        else:
            area_of[b.name] = contact.area
    return nodes_of, area_of, link_of


def source_power(sources, nodes_of: dict, volume) -> np.ndarray:
    """Heat generated inside the solid per node [W]: each :class:`HeatSource`'s ``power`` [W]
    shared by element volume over its nodes ``nodes_of[name]``, or its ``density`` [W/m^3]
    times each element's volume ``volume`` [m^3]."""
    volume = np.asarray(volume, dtype=float)
    q = np.zeros(volume.shape[0])
    for src in sources:
        nodes = nodes_of[src.name]
        v = volume[nodes]
        if src.field("rate") is not None:
            np.add.at(q, nodes, src.field("rate") * v / v.sum())
        else:
            np.add.at(q, nodes, src.field("density") * v)
    return q
