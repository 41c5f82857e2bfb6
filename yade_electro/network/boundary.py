"""The boundary vocabulary of the transport core, physics-blind, checked in one place.

A network carries one quantity (a potential, a temperature) between nodes through
conductances. What a boundary can do to it is the same for every physics:

=====================  ===========================================  ====================================
condition              what it does                                 electrical / thermal name
=====================  ===========================================  ====================================
:class:`FixedValue`    holds a node set (tied: one value) or a      -- / :class:`FixedTemperature`
                       surface of the container at a value
:class:`Terminal`      a node set tied by a perfect conductor, at   ``Electrode`` / --
                       a fixed value or fed a total rate
:class:`Injection`     feeds a rate into a node set or through a    -- / :class:`HeatFlux`
                       surface: in total, or per unit area
:class:`Robin`         exchanges ``k A (ambient - u_i)`` with an    -- / :class:`Convection`
                       ambient value (convection)
:class:`Source`        a volumetric source: in total, or per        -- / :class:`HeatSource`
                       unit volume
=====================  ===========================================  ====================================

A *link* is a fixed value reached through per-node conductances instead of being imposed on
the nodes: a :class:`FixedValue` or a :class:`Terminal` on a surface (each element joined by its
half cell) or on a wall of a granular bed (each particle by its contact). The physics layer
computes the link conductances; the network takes them as ``link_of``.

A physics names its conditions in its own words (``temperature=``, ``h=``, ``potential=``) by
subclassing :class:`Condition` with a ``FIELDS`` table from the generic role to its field
name and a ``UNITS`` table for the messages; the checks below are the only ones, and
:meth:`Condition.generic` gives the physics-blind condition the network works with.

Units: SI, as the physics says (V, A for electricity; K, W for heat).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Dict, Optional

import numpy as np

from ..core.errors import BoundaryConditionError, MaterialError
from ..core.materials import real_number
from ..core.selection import check_selector

__all__ = ["boundary_value", "check_place", "check_area", "terminal_number", "Condition", "TerminalRole",
           "FixedValue", "Terminal", "Injection", "Robin", "Source", "generic", "check_condition"]


def boundary_value(name, v) -> float:
    """``v`` as a finite real number, or a BoundaryConditionError naming ``name``."""
    try:
        return real_number(name, v)
    except MaterialError as exc:
        raise BoundaryConditionError(str(exc)) from None


def check_place(what: str, name, *, elements=None, surface=None, wall=False, elements_key: str = "nodes",
                allow_wall: bool = False) -> None:
    """Check where a condition acts, the one check for every condition: a non-empty ``name``
    and exactly one place, elements (``elements_key=``, a selector), a ``surface`` of the
    container, or (``allow_wall``) a wall of a granular bed; the surface and the selector are
    checked too. BoundaryConditionError saying what to give."""
    if not isinstance(name, str) or not name:
        raise BoundaryConditionError(f"{what} names must be non-empty strings, got {name!r}")
    options = (f"{elements_key}= (elements: a predicate, ids or a mask) or surface= (a surface of the container)"
               + (" or wall= (a wall of a granular bed)" if allow_wall else ""))
    given = (elements is not None) + (surface is not None) + bool(wall)
    if given != 1:
        raise BoundaryConditionError(f"{what} {name!r}: give {options}" + (", not both" if given > 1 else ""))
    if surface is not None:
        from ..geometry.boundary import check_surface
        check_surface(surface, f"{what} {name!r}")
    elif elements is not None:
        check_selector(elements, f"{what} {name!r}: {elements_key}")


def check_area(what: str, name: str, area, surface) -> None:
    """An ``area`` [m^2] given with a condition: a finite number >= 0 or one per element, and
    none with a surface (whose boundary faces give the areas)."""
    if surface is not None:
        if area is not None:
            raise BoundaryConditionError(f"{what} {name!r}: a surface condition takes its areas from the boundary "
                                         "faces on the surface; do not give area=")
        return
    if area is not None and not callable(area):
        try:
            a = np.asarray(area, dtype=float)
        except (TypeError, ValueError):
            raise BoundaryConditionError(f"{what} {name!r}: area must be a number or an array of areas (m^2), "
                                         f"got {area!r}") from None
        if a.ndim > 1 or not np.all(np.isfinite(a)) or np.any(a < 0):
            raise BoundaryConditionError(f"{what} {name!r}: areas must be finite and >= 0 (m^2), a scalar or one "
                                         "per element")


class Condition:
    """What every boundary condition shares: a role, its field names and units, one check.

    Subclasses are frozen dataclasses with a ``name`` and the fields their role needs, named
    by ``FIELDS`` (generic role name -> own field name); ``UNITS`` gives each generic role's
    unit for the messages and ``KIND`` the words a message starts with. ``__post_init__``
    runs the role's check (the only one) and stores the checked numbers."""

    ROLE: ClassVar[str] = ""
    KIND: ClassVar[str] = ""
    FIELDS: ClassVar[Dict[str, str]] = {}
    UNITS: ClassVar[Dict[str, str]] = {}

    def field(self, role: str):
        """The value of the field that plays ``role`` (e.g. ``'value'`` is ``temperature``)."""
        return getattr(self, self.FIELDS.get(role, role))

    def _own(self, role: str) -> str:
        return self.FIELDS.get(role, role)

    def _unit(self, role: str) -> str:
        return self.UNITS.get(role, "")

    def _store(self, role: str, v) -> None:
        object.__setattr__(self, self._own(role), v)

    def __post_init__(self):
        check_condition(self)

    def generic(self) -> "Condition":
        """The physics-blind condition (:class:`FixedValue`, :class:`Terminal`, ...) with the
        same name, place and numbers."""
        cls = _GENERIC[self.ROLE]
        if type(self) is cls:
            return self
        kw = {role: self.field(role) for role in cls.FIELDS}
        for place in ("nodes", "surface", "area"):
            if place in cls.__dataclass_fields__ and hasattr(self, place):
                kw[place] = getattr(self, place)
        return cls(name=self.name, **kw)


def _unit_text(c: Condition, role: str, extra: str = "") -> str:
    unit = c._unit(role)
    inner = ", ".join(p for p in (extra, unit) if p)
    return f" ({inner})" if inner else ""


def _required(c: Condition, role: str) -> None:
    if c.field(role) is None:
        raise BoundaryConditionError(f"{c.KIND} {c.name!r}: give {c._own(role)}={_unit_text(c, role)}")


def _one_of(c: Condition, first: str, second: str, first_note: str = "total", second_note: str = "") -> str:
    """Exactly one of two roles given; stores it checked and returns the role given."""
    if (c.field(first) is None) == (c.field(second) is None):
        a = f"{c._own(first)}= ({', '.join(p for p in (c._unit(first), first_note) if p)})"
        b = f"{c._own(second)}= ({', '.join(p for p in (second_note, c._unit(second)) if p)})"
        raise BoundaryConditionError(f"{c.KIND} {c.name!r}: give exactly one of {a} or {b}")
    role = first if c.field(first) is not None else second
    c._store(role, boundary_value(f"{c.KIND} {c.name!r}: {c._own(role)}", c.field(role)))
    return role


def _check_fixed(c: Condition) -> None:
    check_place(c.KIND, c.name, elements=c.nodes, surface=c.surface)
    _required(c, "value")
    c._store("value", boundary_value(f"{c.KIND} {c.name!r}: {c._own('value')}", c.field("value")))


def _check_terminal(c: Condition) -> None:
    if "nodes" in getattr(c, "__dataclass_fields__", {}):
        raw = np.asarray(c.nodes).reshape(-1)
        if raw.size and not np.issubdtype(raw.dtype, np.integer):
            raise BoundaryConditionError(f"{c.KIND} {c.name!r}: nodes must be integer indices, got "
                                         f"{raw[:5].tolist()}")
        nodes = np.unique(raw.astype(np.int64))
        if nodes.size == 0:
            raise BoundaryConditionError(f"{c.KIND} {c.name!r} selects no element: check its predicate/box, ids "
                                         "or mask against the packing")
        nodes.setflags(write=False)
        object.__setattr__(c, "nodes", nodes)
    if (c.field("value") is None) == (c.field("rate") is None):
        v, r = c._own("value"), c._own("rate")
        raise BoundaryConditionError(f"{c.KIND} {c.name!r}: give exactly one of {v}= (fixed {v}"
                                     f"{', ' + c._unit('value') if c._unit('value') else ''}) or {r}= (imposed {r}"
                                     f"{', ' + c._unit('rate') if c._unit('rate') else ''})")
    role = "value" if c.field("value") is not None else "rate"
    c._store(role, terminal_number(type(c), c.name, c.field(role)))


def terminal_number(cls, name: str, v) -> float:
    """A terminal's fixed value or imposed rate ``v`` as a finite float, in the words of the
    terminal class ``cls`` (``KIND``, ``UNITS``); BoundaryConditionError otherwise. The check
    of a terminal's number, also when a value is changed later."""
    units = getattr(cls, "UNITS", {})
    try:
        return real_number(f"{cls.KIND} {name!r}: value", v,
                           what=f"a real number ({units.get('value') or 'value'} or {units.get('rate') or 'rate'})")
    except MaterialError as exc:
        raise BoundaryConditionError(str(exc)) from None


def _check_injection(c: Condition) -> None:
    check_place(c.KIND, c.name, elements=c.nodes, surface=c.surface)
    check_area(c.KIND, c.name, c.area, c.surface)
    _one_of(c, "rate", "density")


def _check_robin(c: Condition) -> None:
    check_place(c.KIND, c.name, elements=c.nodes, surface=c.surface)
    check_area(c.KIND, c.name, c.area, c.surface)
    _required(c, "coefficient")
    _required(c, "ambient")
    own, unit = c._own("coefficient"), c._unit("coefficient")
    try:
        k = real_number(f"{c.KIND} {c.name!r}: {own}", c.field("coefficient"))
    except MaterialError as exc:
        raise MaterialError(f"{exc}{f' ({unit})' if unit else ''}") from None
    if k < 0:
        raise MaterialError(f"{c.KIND} {c.name!r}: {own} must be >= 0{f' ({unit})' if unit else ''}, got {k}")
    c._store("coefficient", k)
    c._store("ambient", boundary_value(f"{c.KIND} {c.name!r}: {c._own('ambient')}", c.field("ambient")))


def _check_source(c: Condition) -> None:
    if not isinstance(c.name, str) or not c.name:
        raise BoundaryConditionError(f"{c.KIND} names must be non-empty strings, got {c.name!r}")
    if c.nodes is not None:
        check_selector(c.nodes, f"{c.KIND} {c.name!r}: nodes")
    _one_of(c, "rate", "density")


_CHECKS = {"fixed": _check_fixed, "terminal": _check_terminal, "injection": _check_injection,
           "robin": _check_robin, "source": _check_source}


@dataclass(frozen=True)
class FixedValue(Condition):
    """The value held on a node set or at a surface.

    Parameters
    ----------
    name : str
    nodes : selector, optional
        Node indices (or, with a graph, anything :func:`~yade_electro.core.selection.select_nodes`
        takes): those nodes are held at ``value`` (eliminated from the unknowns).
    value : float
        The value held (V, K, ...).
    surface : surface, optional
        A surface of the container instead of nodes: the surface is held at ``value`` and each
        element with boundary faces on it is linked to it through its half cell.
    """

    ROLE: ClassVar[str] = "fixed"
    KIND: ClassVar[str] = "fixed-value condition"
    FIELDS: ClassVar[Dict[str, str]] = {"value": "value"}

    name: str
    nodes: Any = None
    value: Optional[float] = None
    surface: Any = None


class TerminalRole(Condition):
    """What every terminal answers, whatever it calls its numbers: fixed or fed, and how much."""

    ROLE: ClassVar[str] = "terminal"

    @property
    def fixed(self) -> bool:
        """True for a fixed value, False for an imposed rate."""
        return self.field("value") is not None

    @property
    def amount(self) -> float:
        """The fixed value or the imposed rate."""
        return float(self.field("value") if self.fixed else self.field("rate"))


@dataclass(frozen=True)
class Terminal(TerminalRole):
    """Nodes tied by a perfect conductor (one value for all), at a fixed ``value`` or fed a
    total ``rate`` (its value is then an unknown). Give exactly one.

    Parameters
    ----------
    name : str
    nodes : int array
        Node indices.
    value : float, optional
        The fixed value (V, K, ...).
    rate : float, optional
        The total rate fed into the network (A, W, ...).
    """

    KIND: ClassVar[str] = "terminal"
    FIELDS: ClassVar[Dict[str, str]] = {"value": "value", "rate": "rate"}

    name: str
    nodes: Any = None
    value: Optional[float] = None
    rate: Optional[float] = None


@dataclass(frozen=True)
class Injection(Condition):
    """A rate fed into a node set or through a surface: ``rate`` in total, shared in proportion
    to ``area`` (equal shares when None), or ``density`` per unit area times each node's area.
    Negative values extract.

    Parameters
    ----------
    name : str
    nodes : selector, optional
    rate : float, optional
        Total rate (W, A, ...).
    density : float, optional
        Rate per unit area (W/m^2, A/m^2, ...).
    area : float or (n,) array, optional
        Areas [m^2] (None: equal shares for ``rate``, the exposed areas for ``density``).
    surface : surface, optional
        The elements with boundary faces on that surface, with their faces' areas.
    """

    ROLE: ClassVar[str] = "injection"
    KIND: ClassVar[str] = "injection"
    FIELDS: ClassVar[Dict[str, str]] = {"rate": "rate", "density": "density"}

    name: str
    nodes: Any = None
    rate: Optional[float] = None
    density: Optional[float] = None
    area: Any = None
    surface: Any = None


@dataclass(frozen=True)
class Robin(Condition):
    """An exchange ``coefficient A_i (ambient - u_i)`` with an ambient value (convection).

    Parameters
    ----------
    name : str
    nodes : selector, optional
    coefficient : float
        Transfer coefficient per unit area, >= 0 (W/(m^2 K), ...).
    ambient : float
        The ambient value (K, ...).
    area : float or (n,) array, optional
        Areas [m^2] (None: the exposed areas).
    surface : surface, optional
        On the boundary faces of that surface, in series with each element's half cell.
    """

    ROLE: ClassVar[str] = "robin"
    KIND: ClassVar[str] = "Robin condition"
    FIELDS: ClassVar[Dict[str, str]] = {"coefficient": "coefficient", "ambient": "ambient"}

    name: str
    nodes: Any = None
    coefficient: Optional[float] = None
    ambient: Optional[float] = None
    area: Any = None
    surface: Any = None


@dataclass(frozen=True)
class Source(Condition):
    """A volumetric source on a node set (None: every node): ``rate`` in total or ``density``
    per unit volume, shared in proportion to the nodes' volumes. Negative values are sinks.

    Parameters
    ----------
    name : str
    nodes : selector, optional
    rate : float, optional
        Total rate (W, ...).
    density : float, optional
        Rate per unit volume (W/m^3, ...).
    """

    ROLE: ClassVar[str] = "source"
    KIND: ClassVar[str] = "source"
    FIELDS: ClassVar[Dict[str, str]] = {"rate": "rate", "density": "density"}

    name: str
    nodes: Any = None
    rate: Optional[float] = None
    density: Optional[float] = None


def check_condition(condition: Condition) -> None:
    """Run the check of ``condition``'s role: the one place a condition is checked."""
    _CHECKS[condition.ROLE](condition)


_GENERIC = {"fixed": FixedValue, "terminal": Terminal, "injection": Injection, "robin": Robin,
            "source": Source}


def generic(condition: Condition) -> Condition:
    """The physics-blind form of ``condition`` (BoundaryConditionError for anything else)."""
    if not isinstance(condition, Condition):
        raise BoundaryConditionError(f"not a boundary condition: {condition!r}; give FixedValue, Terminal, "
                                     "Injection, Robin or Source (or their thermal and electrical names)")
    return condition.generic()
