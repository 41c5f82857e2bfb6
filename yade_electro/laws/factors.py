"""Conductance laws, in one registry. A law gives the *geometric factor* g_ij [m] of every edge;
the material makes it a conductance.

Structure and values are kept apart: g depends on the geometry only, so

* the electrical conductance is ``c = g / rho_edge`` [S] (:func:`conductance`),
* the thermal conductance is ``G = lambda_edge g`` [W/K],

with the per-edge material of :mod:`yade_electro.core.materials` (mean resistivity, harmonic mean
conductivity: two half rods in series). A change of temperature (rho_e(T)) changes values only;
a move of the elements changes g, never the structure.

A law is an object made by :func:`make_law` (``make_law('voronoi', container=shape)``) with

* ``network(graph) -> (m, 2)`` the node pairs that conduct (the bonds, or for 'voronoi' the
  Voronoi neighbours the bonds support), and
* ``factor(graph, edges) -> (m,)`` the geometric factor of those pairs [m].

It keeps what it computed once (the tessellation of the 'voronoi' law). Unknown names raise
and list the known ones.

Laws
----
continuum
    Paper 000: g = S_ij / l_ij, S_ij = sqrt(S_i S_j), S_i = alpha(n_i) r_i^2 / f_i.
    Parameters: ``threshold`` (eccentricity limit, 0.4) and ``factor`` (f of eccentric
    elements, 2).
voronoi
    Faces of the Voronoi tessellation of the element centres, bounded by the solid's
    ``container`` (a :class:`yade_electro.geometry.shapes.Shape`): g = A_ij / l_ij, exact for uniform
    fields (see :mod:`yade_electro.geometry.voronoi`). Cracks (``crack='facets'``, the default): a face
    of a pair bonded in the reference conducts while its bond is intact; a face of an unbonded
    pair conducts while its elements are linked by at most ``hops`` (3) intact bonds and no
    broken bond's *facet* (its own Voronoi face) lies across the segment between them. ``crack='paths'`` is the earlier rule
    (every face conducts while its elements are linked by <= hops intact bonds), which leaks
    near a crack front. The tessellation is made on the first configuration of an element set
    (or the ``reference`` one: ids, positions, radii, bonds) and kept (small-strain view: the
    faces keep their areas, l_ij follows the elements).
contact
    Constriction of two overlapping spheres (papers 002, 003): g = 2 a, a the radius of the
    contact circle of the lens.
liggghts
    LIGGGHTS' heat-conduction fix: 4 k1 k2 / (k1 + k2) sqrt(pi a^2) = k_edge 2 sqrt(pi) a, so
    g = 2 sqrt(pi) a (k_edge the harmonic mean).
"""
from __future__ import annotations

from typing import Callable, Dict

import numpy as np

from ..core.errors import GraphError, MaterialError
from ..core.graph import ContactGraph
from ..core.materials import electrical_conductance, positive_property
from .transmission import edge_transmission_surface, polyhedron_alpha

__all__ = ["conductance", "geometric_factor", "conductance_laws", "register_conductance_law", "make_law",
           "check_law_name", "needs_container", "law_attribute", "is_contact_law", "unregister_conductance_law", "contact_radius", "edge_lengths", "ConductanceLaw"]

_LAWS: Dict[str, Callable] = {}


def register_conductance_law(name: str):
    """Decorator adding a law class (or factory ``f(**params) -> law``) to the registry."""
    def deco(factory):
        if name in _LAWS:
            raise ValueError(f"conductance law {name!r} is already registered")
        _LAWS[name] = factory
        return factory
    return deco


def unregister_conductance_law(name: str) -> None:
    """Remove a law from the registry (a no-op for unknown names)."""
    _LAWS.pop(name, None)


def conductance_laws() -> tuple:
    """Names of the registered conductance laws."""
    return tuple(sorted(_LAWS))


def check_law_name(law) -> None:
    """Raise KeyError (listing the known laws) for an unknown law name."""
    if isinstance(law, ConductanceLaw):
        return
    if law not in _LAWS:
        raise KeyError(f"unknown conductance law {law!r}; known laws: {', '.join(conductance_laws())}")


def needs_container(law) -> bool:
    """True when the law ``law`` (a name or a law object) is bounded by the solid's container."""
    if isinstance(law, ConductanceLaw):
        return bool(law.needs_container)
    check_law_name(law)
    return bool(getattr(_LAWS[law], "needs_container", False))


def law_attribute(law, name: str, default=None):
    """A class attribute of the law ``law`` (a name or a law object): e.g. ``cell_volumes``
    (the law makes its elements' cell volumes, hence the capacities) or ``clumps`` (the clump
    mode its reader must have)."""
    if isinstance(law, ConductanceLaw):
        return getattr(law, name, default)
    check_law_name(law)
    return getattr(_LAWS[law], name, default)


def is_contact_law(law) -> bool:
    """True for a law of contacts between particles (a granular bed), False for a law of
    bonded solids; ``law`` is a name or a law object."""
    if isinstance(law, ConductanceLaw):
        return isinstance(law, GranularLaw)
    check_law_name(law)
    cls = _LAWS[law]
    return isinstance(cls, type) and issubclass(cls, GranularLaw)


def make_law(law="continuum", **params) -> "ConductanceLaw":
    """A law object from its name and parameters (a law object is passed through)."""
    if isinstance(law, ConductanceLaw):
        if params:
            raise ValueError("give parameters to make_law only with a law name")
        return law
    check_law_name(law)
    cls = _LAWS[law]
    import inspect
    accepted = inspect.signature(cls.__init__).parameters
    if not any(p.kind is p.VAR_KEYWORD for p in accepted.values()):
        unknown = sorted(set(params) - set(accepted))
        if "crack" in unknown or "hops" in unknown:
            raise ValueError(f"law {law!r} has no Voronoi faces, so it takes no crack rule (crack=, hops=): its "
                             "network is the intact bonds, and a broken bond simply stops conducting. Use "
                             "law='voronoi' (container=...) for the crack rules")
        if unknown:
            known = sorted(k for k in accepted if k != "self")
            raise ValueError(f"law {law!r} takes no parameter(s) {unknown}; its parameters: {known}")
    return cls(**params)


def edge_lengths(graph: ContactGraph, edges) -> np.ndarray:
    """Centre-to-centre distance of node pairs [m]; MaterialError for coincident centres.
    Compiled (:func:`yade_electro.native.pair_lengths`); other pairs than the edges of a
    periodic graph (whose shifts the graph does not hold) by :meth:`ContactGraph.edge_vectors`."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if graph.shift is None or edges is graph.edges:
        from ..native import pair_lengths
        length, zero = pair_lengths(graph.pos, edges, graph.shift)
        if zero:
            raise MaterialError("two connected elements have coincident centres (l_ij = 0)")
        return length
    return _periodic_lengths(graph, edges)


def _periodic_lengths(graph: ContactGraph, edges) -> np.ndarray:
    d = graph.edge_vectors(edges)
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    if np.any(length <= 0):
        raise MaterialError("two connected elements have coincident centres (l_ij = 0)")
    return length


class ConductanceLaw:
    """Base of the laws: the network is the bond graph, g comes from :meth:`factor`."""

    name = "?"
    #: True when the law needs the solid's container (a Shape)
    needs_container = False

    def network(self, graph: ContactGraph) -> np.ndarray:
        """Node pairs (m, 2), i < j, that conduct on ``graph``."""
        return graph.edges

    def factor(self, graph: ContactGraph, edges=None) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _edges(self, graph, edges):
        return graph.edges if edges is None else np.asarray(edges, dtype=np.int64).reshape(-1, 2)

    def wall_factor(self, radius, overlap) -> np.ndarray:
        """g [m] of sphere-wall contacts; only the contact laws have them."""
        raise ValueError(f"law {self.name!r} has no sphere-wall contacts: walls conduct in the granular mode, with a "
                         "contact law (law='contact' or 'liggghts', bonds='contacts')")


@register_conductance_law("continuum")
class ContinuumLaw(ConductanceLaw):
    """Paper 000 eq. 4-5: g = sqrt(S_i S_j) / l_ij on the bonds (compiled,
    :func:`yade_electro.native.continuum_factors`; a periodic graph's bonds, which cross the
    cell, by numpy)."""

    name = "continuum"

    def __init__(self, threshold: float = 0.4, factor: float = 2.0):
        self.threshold, self.factor_ = float(threshold), float(factor)

    def factor(self, graph, edges=None):
        edges = self._edges(graph, edges)
        if edges is not graph.edges and not np.array_equal(edges, graph.edges):
            raise ValueError("the continuum law conducts through the bonds of the graph only")
        if graph.shift is None:
            from ..native import continuum_factors
            g, coincident = continuum_factors(graph.pos, graph.radius, polyhedron_alpha(graph.degree) * graph.radius ** 2,
                                              graph.edges, self.threshold, self.factor_)
            if coincident:
                raise MaterialError("two connected elements have coincident centres (l_ij = 0)")
            return g
        return self.periodic_factor(graph, edges)

    def periodic_factor(self, graph, edges):
        """g of the bonds of a periodic graph (numpy: the eccentricities and surfaces of
        :mod:`yade_electro.laws.transmission`)."""
        s = edge_transmission_surface(graph, threshold=self.threshold, factor=self.factor_)
        return s / edge_lengths(graph, edges)


#: contact-radius models of the contact laws
CONTACT_RADII = ("geometric", "hertz")


def contact_radius(graph: ContactGraph, edges=None, model: str = "geometric") -> np.ndarray:
    """Radius a [m] of the contact circle of each edge's two overlapping spheres (0 where
    they do not overlap).

    ``model='geometric'``: the circle where the two spheres' surfaces cross (the lens of the
    overlap), a^2 = r1^2 - ((r1^2 - r2^2 + d^2) / (2 d))^2, about sqrt(2 R* delta) for small
    overlaps. ``model='hertz'``: the Hertz contact radius a = sqrt(R* delta), R* = r1 r2 /
    (r1 + r2), delta = r1 + r2 - d; for a Hertz contact under a force F (YADE's
    Hertz-Mindlin law), a = (3 F R* / (4 E*))^(1/3).

    Compiled (:func:`yade_electro.native.contact_radii`); other pairs than the edges of a
    periodic graph by numpy.
    """
    if model not in CONTACT_RADII:
        raise ValueError(f"contact radius model must be one of {CONTACT_RADII}, got {model!r}")
    edges = graph.edges if edges is None else np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if graph.shift is None or edges is graph.edges:
        from ..native import contact_radii
        a, coincident = contact_radii(graph.pos, graph.radius, edges, graph.shift, model)
        if coincident:
            raise MaterialError("two connected elements have coincident centres (l_ij = 0)")
        return a
    return _periodic_contact_radius(graph, edges, model)


def _periodic_contact_radius(graph: ContactGraph, edges, model: str) -> np.ndarray:
    r1 = graph.radius[edges[:, 0]]
    r2 = graph.radius[edges[:, 1]]
    d = edge_lengths(graph, edges)
    if model == "hertz":
        delta = np.clip(r1 + r2 - d, 0.0, None)
        return np.sqrt(r1 * r2 / (r1 + r2) * delta)
    x = (r1 ** 2 - r2 ** 2 + d ** 2) / (2.0 * d)
    a2 = r1 ** 2 - x ** 2
    a2 = np.where(d < r1 + r2, a2, 0.0)
    return np.sqrt(np.clip(a2, 0.0, None))


#: exponents of the softened-stiffness correction a_real = a_sim s^k, s = E*_sim / E*_real
STIFFNESS_CORRECTIONS = {"hertz": 1.0 / 3.0, "hooke": 0.5, "lethe": 0.2}


class GranularLaw(ConductanceLaw):
    """Base of the contact laws: a contact radius model, an optional softened-stiffness
    correction, and sphere-wall contacts.

    A DEM run often softens the particles (Young's modulus E*_sim below the real E*_real) to
    afford a longer time step; the overlaps, hence the contact radii, are then too large.
    ``stiffness_ratio`` s = E*_sim / E*_real (0 < s <= 1) scales the radius by s^k:

    * ``correction='hertz'`` (default), k = 1/3: at a given force a Hertz contact radius goes
      as E*^(-1/3); the area as s^(2/3), LIGGGHTS' ``area_correction`` for Hertz;
    * ``'hooke'``, k = 1/2: a linear spring's overlap goes as 1/k_n, the area as s
      (LIGGGHTS' exponent 1 for Hooke);
    * ``'lethe'``, k = 1/5: the radius correction Lethe uses (after Morris et al. 2016,
      which matches the heat of colliding, not resting, particles).

    ``film`` [ohm m^2]: the specific electrical resistance of a surface film (an oxide, a
    contamination layer) on every contact, sphere-sphere and sphere-wall, in series with the
    constriction: a contact's resistance is ``rho_e / g + film / (pi a^2)`` (Holm: the
    constriction of the contact spot plus the film across its area). Electrical only: heat
    crosses the contact by the constriction (default 0: no film).
    """

    def __init__(self, radius: str = "geometric", stiffness_ratio: float = 1.0, correction: str = "hertz",
                 film: float = 0.0):
        if radius not in CONTACT_RADII:
            raise ValueError(f"radius must be one of {CONTACT_RADII}, got {radius!r}")
        try:
            s = float(stiffness_ratio)
        except (TypeError, ValueError):
            raise ValueError(f"stiffness_ratio must be a number in (0, 1] (E*_sim / E*_real), got "
                             f"{stiffness_ratio!r}") from None
        if not (0.0 < s <= 1.0):
            raise ValueError(f"stiffness_ratio must be in (0, 1] (E*_sim / E*_real: the simulated stiffness over "
                             f"the real one), got {stiffness_ratio!r}")
        if correction not in STIFFNESS_CORRECTIONS:
            raise ValueError(f"correction must be one of {sorted(STIFFNESS_CORRECTIONS)}, got {correction!r}")
        self.radius, self.stiffness_ratio, self.correction = radius, s, correction
        self._scale = s ** STIFFNESS_CORRECTIONS[correction]
        try:
            film = float(film)
        except (TypeError, ValueError):
            raise ValueError(f"film must be a number >= 0 (ohm m^2, a film's specific resistance), got {film!r}") from None
        if not (np.isfinite(film) and film >= 0):
            raise ValueError(f"film must be finite and >= 0 (ohm m^2, a film's specific resistance), got {film!r}")
        self.film = film

    def film_resistance(self, graph, edges=None) -> np.ndarray:
        """The film's resistance ``film / (pi a^2)`` [ohm] of each edge's contact (inf where
        a = 0, 0 everywhere without a film)."""
        a = self.contact_radius(graph, edges)
        return _film(self.film, a)

    def wall_film_resistance(self, radius, overlap) -> np.ndarray:
        """The film's resistance [ohm] of spheres of ``radius`` pressed by ``overlap`` into a wall."""
        from ..geometry.contacts import plane_contact_radius
        return _film(self.film, self._scale * plane_contact_radius(radius, overlap, self.radius))

    #: g per unit contact radius [-]
    SHAPE = 2.0

    def contact_radius(self, graph, edges=None) -> np.ndarray:
        """Corrected contact radius a [m] of each edge."""
        return self._scale * contact_radius(graph, self._edges(graph, edges), self.radius)

    def factor(self, graph, edges=None):
        return self.SHAPE * self.contact_radius(graph, edges)

    def wall_factor(self, radius, overlap) -> np.ndarray:
        """g [m] of spheres of ``radius`` pressed by ``overlap`` into a wall (a plane)."""
        from ..geometry.contacts import plane_contact_radius
        return self.SHAPE * self._scale * plane_contact_radius(radius, overlap, self.radius)


def _film(film: float, a) -> np.ndarray:
    a = np.asarray(a, float)
    if film == 0.0:
        return np.zeros(a.shape)
    with np.errstate(divide="ignore"):
        return np.where(a > 0, film / (np.pi * a * a), np.inf)


@register_conductance_law("contact")
class ContactLaw(GranularLaw):
    """Constriction of overlapping spheres (papers 002, 003): g = 2 a (heat: H = 2 k a;
    current: 2 a / rho_e). ``radius``: 'geometric' (lens of the overlap) or 'hertz' (see
    :func:`contact_radius`); ``stiffness_ratio``, ``correction``: see :class:`GranularLaw`."""

    name = "contact"
    SHAPE = 2.0


@register_conductance_law("liggghts")
class LiggghtsLaw(GranularLaw):
    """LIGGGHTS' form 4 k1 k2 / (k1 + k2) sqrt(pi a^2) = k_edge 2 sqrt(pi) a: g = 2 sqrt(pi) a;
    ``radius`` and the stiffness correction as for the contact law."""

    name = "liggghts"
    SHAPE = 2.0 * np.sqrt(np.pi)


@register_conductance_law("pipe")
class PipeLaw(GranularLaw):
    """Feng's pipe network (Feng, Han, Owen, Powder Technol. 193, 2009; paper 003 section 5):
    the thermal resistance per unit length of a long cylinder (a 2D disc) from its centre to a
    contact arc of half angle alpha is R = (-ln alpha + 3/2 + alpha^2 / 36) / (pi k) (within
    high accuracy for alpha below 30 degrees), and two cylinders in contact are the two in
    series (a perfect contact, R_c* = 0). Over a cylinder length ``width`` [m], g = pi width /
    (f(alpha_1) + f(alpha_2)), f the bracket, sin alpha_i = a / r_i with a the half chord of
    the contact (the ``radius`` model's contact radius).

    It is a 2D model: the spheres of the graph stand for the cross-sections of parallel
    cylinders of length ``width`` (paper 003 compares it with two thin cylinders). It is not a
    sphere-sphere law; for spheres use 'contact' or 'liggghts'. With two conductivities the
    edge takes their harmonic mean, exact when alpha_1 = alpha_2 (equal radii)."""

    name = "pipe"

    def __init__(self, width: float = None, radius: str = "geometric", stiffness_ratio: float = 1.0,
                 correction: str = "hertz", film: float = 0.0):
        super().__init__(radius, stiffness_ratio, correction, film)
        try:
            w = float(width)
        except (TypeError, ValueError):
            raise ValueError("law 'pipe' needs width= (the length of the cylinders the discs stand for, m), got "
                             f"{width!r}") from None
        if not (np.isfinite(w) and w > 0):
            raise ValueError(f"law 'pipe': width must be finite and > 0 (m), got {width!r}")
        self.width = w

    @staticmethod
    def pipe_bracket(alpha) -> np.ndarray:
        """f(alpha) = -ln alpha + 3/2 + alpha^2 / 36 (inf at alpha = 0)."""
        a = np.asarray(alpha, float)
        with np.errstate(divide="ignore"):
            return -np.log(a) + 1.5 + a ** 2 / 36.0

    def factor(self, graph, edges=None):
        e = self._edges(graph, edges)
        a = self.contact_radius(graph, e)
        r1, r2 = graph.radius[e[:, 0]], graph.radius[e[:, 1]]
        al1 = np.arcsin(np.clip(a / r1, 0.0, 1.0))
        al2 = np.arcsin(np.clip(a / r2, 0.0, 1.0))
        f = self.pipe_bracket(al1) + self.pipe_bracket(al2)
        return np.where(a > 0, np.pi * self.width / f, 0.0)

    def wall_factor(self, radius, overlap) -> np.ndarray:
        from ..geometry.contacts import plane_contact_radius
        r = np.asarray(radius, float)
        a = self._scale * plane_contact_radius(r, overlap, self.radius)
        al = np.arcsin(np.clip(a / r, 0.0, 1.0))
        # the wall is a half-space: only the particle's pipe resistance
        return np.where(a > 0, np.pi * self.width / self.pipe_bracket(al), 0.0)


@register_conductance_law("voronoi")
class VoronoiLaw(ConductanceLaw):
    """g = A_ij / l_ij, A_ij the Voronoi face of i and j inside the container."""

    name = "voronoi"
    needs_container = True

    def __init__(self, container=None, hops: int = 3, reference=None, crack: str = "facets", radius_range=None,
                 bounds=None):
        if container is None or not (hasattr(container, "sdf") and hasattr(container, "gradient")):
            raise ValueError("the 'voronoi' law needs container=<the solid's shape>, an object with sdf(x) "
                             "and gradient(x) (e.g. yade_electro.geometry.shapes.as_shape(predicate)); "
                             f"got {container!r}")
        if isinstance(hops, bool) or int(hops) != hops or hops < 1:
            raise ValueError(f"hops must be an integer >= 1, got {hops!r}")
        if crack not in ("facets", "paths"):
            raise ValueError(f"crack must be 'facets' (the broken bonds' facets cut the faces across them) or "
                             f"'paths' (a face conducts while its elements are linked by <= hops bonds), got {crack!r}")
        self.container, self.hops, self.crack = container, int(hops), crack
        # reference: (ids, pos, radius[, bonds]) of the configuration the faces are made on
        self.reference = None if reference is None else tuple(np.asarray(a) for a in reference)
        self._faces = None
        self._key = None
        self.tessellations = 0
        #: (r_min, r_max) [m] of the whole packing when the graphs are a part of it (a
        #: distributed rank's region; see :func:`~yade_electro.geometry.cells.bounded_cells`)
        self.radius_range = None if radius_range is None else (float(radius_range[0]), float(radius_range[1]))
        #: (lo, hi) [m] of the whole packing's centres, likewise
        self.bounds = bounds
        #: how often the faces' areas were looked up for an edge list (once per list)
        self.area_lookups = 0

    def faces(self, graph: ContactGraph):
        """The kept tessellation's faces, made once per element set: on ``reference`` (ids,
        pos, radius) when it holds the same elements (a resumed run), else on the first graph
        of the set, taken back to the container's frame by the rigid motion of the elements it
        shares with the last reference (:func:`~yade_electro.geometry.rigid.back_to_reference`:
        a solid moved as a whole and then restructured keeps its cells)."""
        key = graph.ids.tobytes()
        if self._key != key:
            from ..geometry.voronoi import VoronoiFaces
            ref = self.reference
            if ref is not None and ref[0].shape == graph.ids.shape and np.array_equal(ref[0], graph.ids):
                bonds = ref[3] if len(ref) > 3 else graph.edges
                base = ContactGraph(ref[1], ref[2], bonds, ref[0])
            else:
                base = graph
                if ref is not None:       # the solid moved since: back to the container's frame
                    from ..geometry.rigid import back_to_reference
                    back = back_to_reference(ref[0], ref[1], graph.ids, graph.pos,
                                             1e-9 * float(np.max(graph.radius)) if graph.n_nodes else 0.0)
                    if back is not None:
                        base = ContactGraph(back, graph.radius, graph.edges, graph.ids)
            self._faces = VoronoiFaces.of(base, self.container, self.radius_range, self.bounds)
            self.reference = (base.ids.copy(), np.array(base.pos), np.array(base.radius), np.array(base.edges))
            self._key = key
            self.tessellations += 1
        return self._faces

    def network(self, graph):
        faces = self.faces(graph)
        if self.crack == "paths":
            return faces.supported_pairs(graph.edges, self.hops)
        return faces.cracked(self.reference[1], graph.edges, self.reference[3], self.hops)

    def factor(self, graph, edges=None):
        edges = self._edges(graph, edges)
        faces = self.faces(graph)
        # the areas of one edge list are looked up once (moves change the lengths only); the
        # edges come as a new view at every call, so they are compared, not their id
        kept = getattr(self, "_area_edges", None)
        if getattr(self, "_area_faces", None) is not faces or not (
                edges is kept or (kept is not None and np.array_equal(edges, kept))):
            self._area_of_edges = faces.area_of(edges)
            self._area_faces, self._area_edges = faces, edges
            self.area_lookups += 1
        return self._area_of_edges / edge_lengths(graph, edges)

    def cell_volumes(self, graph) -> np.ndarray:
        """Bounded Voronoi cell volumes [m^3] from the kept tessellation; GraphError naming the
        elements whose cell is empty (they lie outside the container)."""
        v = self.faces(graph).cell_volumes()
        bad = ~(np.isfinite(v) & (v > 0))
        if np.any(bad):
            ids = np.asarray(graph.ids)[bad]
            raise GraphError(f"{ids.size} element(s) have no cell inside the container, so no volume and no heat "
                             f"capacity: bodies {ids[:10].tolist()}{' ...' if ids.size > 10 else ''} lie outside the "
                             "solid (a loose sphere dropped outside it?). Leave them out of the engine (a mask, or "
                             "Reader(isolated='leave out') when they have no bond), or erase them")
        return v


def geometric_factor(graph: ContactGraph, law="continuum", **params) -> np.ndarray:
    """g [m] of every edge of ``graph`` by the named law (one-shot; see :func:`make_law`)."""
    return make_law(law, **params).factor(graph, graph.edges)


def conductance(graph: ContactGraph, resistivity, law="continuum", **params) -> np.ndarray:
    """Conductance of every edge of ``graph`` [S] (or [W/K] with a thermal resistivity 1/lambda):
    ``g / rho_edge``.

    Raises
    ------
    KeyError
        Unknown law; the message lists the known ones.
    MaterialError
        Resistivity not finite and positive.
    """
    law = make_law(law, **params)
    rho = positive_property("resistivity", resistivity, graph.n_nodes, " (ohm m for electrical resistivity)")
    g = law.factor(graph, graph.edges)
    c = electrical_conductance(g, rho, graph.edges, series=getattr(law, "film", 0.0) and law.film_resistance(graph))
    if not np.all(np.isfinite(c)) or np.any(c < 0):
        raise MaterialError(f"conductance law {law.name!r} produced non-finite or negative values")
    return c
