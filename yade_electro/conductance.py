"""Edge conductance laws, in one registry.

A law is a pure function ``law(graph, resistivity, **params) -> c`` that returns the
electrical conductance c_ij [S] of every edge of a :class:`ContactGraph`. The same laws
give thermal conductances when called with the thermal resistivity 1/lambda [m K / W]
(the result is then in W/K).

``resistivity`` is a positive scalar [ohm m] or one value per node; with per-node values an
edge is two half-length rods in series: R_ij = (rho_i + rho_j) / 2 * l_ij / S_ij.

Laws
----
continuum
    Paper 000: c_ij = S_ij / (rho l_ij), S_ij = sqrt(S_i S_j), S_i = alpha(n_i) r_i^2 / f_i.
    Parameters: ``threshold`` (eccentricity limit, 0.4) and ``factor`` (f for eccentric
    elements, 2).
contact
    Constriction conductance of two overlapping spheres (papers 002, 003): c = 2 a / rho,
    a the radius of the contact circle of the lens.
voronoi
    Faces of the Voronoi tessellation of the element centres, bounded by the solid's
    ``container`` (required: an object with ``sdf`` and ``gradient``, e.g. a shape of
    ``yade_electro.yade.packing``): c_ij = A_ij / (rho l_ij). Exact for uniform fields, no
    constant to choose (see ``yade_electro.voronoi``). A face conducts while its two
    elements are linked by a path of at most ``hops`` (default 3) intact bonds, so cracks
    (broken bonds) cut the current; the faces are computed once on the first configuration.
liggghts
    The form LIGGGHTS' heat-conduction fix uses: c = 4 k1 k2 / (k1 + k2) sqrt(pi a^2),
    k = 1/rho; for equal materials c = 2 sqrt(pi) a / rho.
"""
from __future__ import annotations

from typing import Callable, Dict, Optional

import numpy as np

from .errors import MaterialError
from .graph import ContactGraph
from .surfaces import edge_transmission_surface

__all__ = ["conductance", "conductance_laws", "network_graph", "register_conductance_law", "check_resistivity",
           "contact_radius", "edge_resistivity"]

_LAWS: Dict[str, Callable] = {}
_EXPANDERS: Dict[str, Callable] = {}


def register_conductance_law(name: str, expand: Optional[Callable] = None):
    """Decorator that adds a law ``f(graph, resistivity, **params) -> (m,) array`` to the registry.

    ``expand(graph, **params) -> graph``, optional, gives the network the law conducts on
    when it is not the bond graph itself (the ``voronoi`` law adds the faces of non-bonded
    Voronoi neighbours); see :func:`network_graph`.
    """
    def deco(fn):
        if name in _LAWS:
            raise ValueError(f"conductance law {name!r} is already registered")
        _LAWS[name] = fn
        if expand is not None:
            _EXPANDERS[name] = expand
        return fn
    return deco


def network_graph(graph: ContactGraph, law: str = "continuum", **params) -> ContactGraph:
    """The graph whose edges carry current under ``law``: the bond graph itself, or (for laws
    with an expander, e.g. 'voronoi') a graph with the same nodes and more edges."""
    _law(law)
    fn = _EXPANDERS.get(law)
    return graph if fn is None else fn(graph, **params)


def _law(law):
    try:
        return _LAWS[law]
    except KeyError:
        raise KeyError(f"unknown conductance law {law!r}; known laws: {', '.join(conductance_laws())}") from None


def conductance_laws() -> tuple:
    """Names of the registered conductance laws."""
    return tuple(sorted(_LAWS))


def check_resistivity(resistivity, n_nodes: int, name: str = "resistivity") -> np.ndarray:
    """Return ``resistivity`` as a float array (scalar or (n,)), or raise MaterialError if it is
    not finite and strictly positive."""
    rho = np.asarray(resistivity, dtype=float)
    if rho.ndim not in (0, 1) or (rho.ndim == 1 and rho.shape[0] != n_nodes):
        raise MaterialError(f"{name} must be a scalar or one value per element ({n_nodes}), "
                            f"got shape {rho.shape}")
    if not np.all(np.isfinite(rho)) or np.any(rho <= 0):
        bad = rho if rho.ndim == 0 else rho[~(np.isfinite(rho) & (rho > 0))][:5]
        raise MaterialError(f"{name} must be finite and > 0 (SI units, ohm m for electrical "
                            f"resistivity); got {np.atleast_1d(bad).tolist()}")
    return rho


def edge_resistivity(graph: ContactGraph, rho: np.ndarray) -> np.ndarray:
    """Resistivity of each edge: the scalar, or the mean of the two end nodes' values."""
    if rho.ndim == 0:
        return np.full(graph.n_edges, float(rho))
    return 0.5 * (rho[graph.edges[:, 0]] + rho[graph.edges[:, 1]])


def conductance(graph: ContactGraph, resistivity, law: str = "continuum", **params) -> np.ndarray:
    """Conductance of every edge [S] (or [W/K] with a thermal resistivity) by the named law.

    Raises
    ------
    KeyError
        Unknown law; the message lists the known ones.
    MaterialError
        Resistivity not finite and positive.
    """
    fn = _law(law)
    rho = check_resistivity(resistivity, graph.n_nodes)
    c = fn(graph, rho, **params)
    if not np.all(np.isfinite(c)) or np.any(c < 0):
        raise MaterialError(f"conductance law {law!r} produced non-finite or negative values")
    return c


@register_conductance_law("continuum")
def continuum_conductance(graph: ContactGraph, rho, threshold: float = 0.4, factor: float = 2.0):
    """Paper 000 eq. 4-5: c_ij = sqrt(S_i S_j) / (rho l_ij)."""
    s = edge_transmission_surface(graph, threshold=threshold, factor=factor)
    length = graph.length
    if np.any(length <= 0):
        raise MaterialError("two bonded elements have coincident centres (l_ij = 0)")
    return s / (edge_resistivity(graph, rho) * length)


def contact_radius(graph: ContactGraph) -> np.ndarray:
    """Radius a [m] of the contact circle of each edge's two overlapping spheres (0 where
    they do not overlap): a^2 = r1^2 - ((r1^2 - r2^2 + d^2) / (2 d))^2."""
    r1 = graph.radius[graph.edges[:, 0]]
    r2 = graph.radius[graph.edges[:, 1]]
    d = graph.length
    x = (r1 ** 2 - r2 ** 2 + d ** 2) / (2.0 * d)
    a2 = r1 ** 2 - x ** 2
    a2 = np.where(d < r1 + r2, a2, 0.0)
    return np.sqrt(np.clip(a2, 0.0, None))


@register_conductance_law("contact")
def contact_conductance(graph: ContactGraph, rho):
    """Constriction conductance 2 a / rho of overlapping spheres (papers 002, 003)."""
    return 2.0 * contact_radius(graph) / edge_resistivity(graph, rho)


@register_conductance_law("liggghts")
def liggghts_conductance(graph: ContactGraph, rho):
    """LIGGGHTS' form 4 k1 k2 / (k1 + k2) sqrt(pi a^2), k = 1/rho of each node."""
    if rho.ndim == 0:
        k1 = k2 = 1.0 / float(rho)
    else:
        k1, k2 = 1.0 / rho[graph.edges[:, 0]], 1.0 / rho[graph.edges[:, 1]]
    return 4.0 * k1 * k2 / (k1 + k2) * np.sqrt(np.pi) * contact_radius(graph)


def _voronoi_faces_for(graph: ContactGraph, container, cache):
    from .voronoi import VoronoiFaces
    if container is None or not (hasattr(container, "sdf") and hasattr(container, "gradient")):
        raise ValueError("the 'voronoi' law needs container=<the solid's shape>, an object with sdf(x) "
                         "and gradient(x) (e.g. yade_electro.yade.packing.as_shape(predicate)); "
                         f"got {container!r}")
    # the tessellation is made once, on the first (reference) configuration, and kept while
    # the same elements are there: moving elements change l_ij, not the face areas
    # (small-strain view); a new element set, or ElectricalModel.reset(), makes it anew
    key = ("voronoi", graph.n_nodes, graph.ids.tobytes(), id(container))
    if cache is not None and cache.get("key") == key:
        return cache["faces"]
    faces = VoronoiFaces.of(graph, container)
    if cache is not None:
        cache.clear()
        cache.update(key=key, faces=faces, container=container)
    return faces


def _voronoi_expand(graph: ContactGraph, container=None, cache=None, hops: int = 3):
    faces = _voronoi_faces_for(graph, container, cache)
    return graph.with_edges(faces.supported_pairs(graph.edges, hops), revision=graph.revision)


@register_conductance_law("voronoi", expand=_voronoi_expand)
def voronoi_conductance(graph: ContactGraph, rho, container=None, cache=None, hops: int = 3):
    """c_ij = A_ij / (rho l_ij), A_ij the Voronoi face of i and j inside the container."""
    faces = _voronoi_faces_for(graph, container, cache)
    return faces.area_of(graph.edges) / (edge_resistivity(graph, rho) * graph.length)
