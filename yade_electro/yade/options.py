"""The option objects of the engines, each documented once: how the scene is read
(:class:`Reader`), what is written (:class:`Output`), where current enters (:class:`Electrode`),
the walls of a granular bed (:class:`Wall`), several YADE materials (:class:`Materials`) and
the starting temperatures (:class:`InitialTemperature`).

The material (:class:`~yade_electro.core.materials.Material`), the conductance law
(:class:`~yade_electro.laws.law.Law`), the time integration
(:class:`~yade_electro.physics.integrator.Integrator`) and the thermal conditions
(:class:`~yade_electro.network.heat_conditions.FixedTemperature`, ``HeatFlux``, ``Convection``,
``HeatSource``) are the core's own objects, which the models take too.

Units: SI (m, V, A, K, ohm m, kg/m^3, J/(kg K), W/(m K)).
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional, Tuple, Union

import numpy as np

from ..core.errors import BoundaryConditionError, MaterialError
from ..core.materials import Material, real_number
from ..laws.law import Law
from ..network.kirchhoff import PotentialOrCurrent

__all__ = ["Reader", "Output", "Electrode", "Wall", "Materials", "InitialTemperature", "electrodes_from_dict",
           "walls_from_dict", "electrical_settings", "thermal_settings", "HEAT_ROLES"]


def _body_ids(what: str, ids) -> list:
    if isinstance(ids, (bool, np.bool_)):
        raise BoundaryConditionError(f"{what}: give body id(s), got {ids!r}")
    if isinstance(ids, (numbers.Integral, np.integer)):
        return [int(ids)]
    try:
        out = [int(i) for i in ids]
    except (TypeError, ValueError):
        raise BoundaryConditionError(f"{what}: give body id(s) (an int or a list of ints), got {ids!r}") from None
    if not out:
        raise BoundaryConditionError(f"{what}: the list of body ids is empty")
    return out


@dataclass(frozen=True)
class Reader:
    """How an engine reads the scene, and what it treats as a change.

    Parameters
    ----------
    bonds : {'cohesive', 'contacts'}
        ``'cohesive'`` (default): a bonded solid; the edges are the intact cohesive bonds
        (``CohFrictPhys``, ``JCFpmPhys``). ``'contacts'``: a granular bed; the edges are the
        sphere-sphere contacts (overlaps), walls and facets can take part (:class:`Wall`,
        ``Electrode(wall=...)``), periodic cells conduct heat.
    mask : int, optional
        Only spheres with ``b.mask & mask`` take part.
    geometry_every : int
        Bonded solids: read the positions every this many calls (default 10); a move beyond
        ``move_tolerance`` gives new geometric factors (the structure is kept).
    move_tolerance : float
        Largest move of an element, in its radii, that is not a change (default 1e-4).
    full_read_every : int
        Read every body and interaction every this many calls even when YADE's counters say
        nothing changed (default 0: only when a change is seen). Set it when bonds are made
        during the run (``setCohesionNow``): the cheap checks cannot see that.
    bond_check : {'auto', 'sweep', 'flags', 'counters', 'count'}
        How bonds that break with no counter change are found: ``'sweep'`` reads
        1/``sweep_calls`` of the bond flags per call, ``'flags'`` all of them every call,
        ``'counters'`` YADE's JCFpm crack counters; ``'auto'`` picks the counters with JCFpm,
        else reads at most 2,500 flags a call: all of them up to 2,500 bonds, else a sweep
        over the calls that needs, ``sweep_calls`` at most (see :mod:`yade_electro.yade.scene`). The history rows'
        ``bond_check_calls`` say within how many calls a break is seen.
    sweep_calls : int
        Calls over which ``'sweep'`` reads every bond once (default 8).
    skin : 'auto' or float
        Granular beds: the Verlet skin in smallest radii (default: adapted to the motion).
    isolated : {'keep', 'leave out'}
        Bonded solids: spheres with no bond (a particle the bonding missed, a loose sphere
        dropped in). ``'keep'`` (default): they are elements that conduct nothing (floating:
        they keep their heat and carry no current, a warning names them); one lying outside
        the container is an error naming it. ``'leave out'``: they are not elements (a log
        warning names them at each full read that leaves some out).
    reselect : bool
        Select element-layer electrodes and conditions again on each new structure, instead
        of keeping them by body id (default False).
    overlap : bool
        Heat-only engines in a granular bed: run each call's numpy work on a worker thread
        while YADE steps on; results reach the bodies one call later (default False). Pays
        only when YADE leaves a core free.
    clumps : {'lumped', 'resolved'}, optional
        Granular beds: clumps of spheres (``O.bodies.appendClumped``) conduct, their members
        being spheres. ``'lumped'`` (the default in a granular bed): one temperature per clump,
        its members' capacities added, the conductances between members of two clumps added
        per clump pair; ``'resolved'``: each member its own temperature, members of one clump
        joined through the lens where they overlap (see
        :mod:`yade_electro.network.lumping`). Currents flow member by member in both. The
        temperature is written on the members and on the clump body. In a bonded solid
        (``bonds='cohesive'``) the members are elements bonded to their neighbours by YADE's
        cohesive interactions, and to the members of their own clump where their spheres are
        closer than 1.04 times their radii's sum (YADE makes no interaction inside a clump;
        those bonds never break); ``'lumped'`` and ``'resolved'`` as above, and without
        ``clumps`` a bonded solid leaves clumps out (a warning).
    """

    bonds: str = "cohesive"
    mask: Optional[int] = None
    geometry_every: int = 10
    move_tolerance: float = 1e-4
    full_read_every: int = 0
    bond_check: str = "auto"
    sweep_calls: int = 8
    skin: Any = "auto"
    reselect: bool = False
    overlap: bool = False
    clumps: Optional[str] = None
    isolated: str = "keep"

    def __post_init__(self):
        if self.bonds not in ("cohesive", "contacts"):
            raise ValueError(f"Reader bonds must be 'cohesive' (a bonded solid) or 'contacts' (a granular bed), "
                             f"got {self.bonds!r}")
        for name in ("reselect", "overlap"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"Reader {name} must be True or False, got {getattr(self, name)!r}")
        if self.isolated not in ("keep", "leave out"):
            raise ValueError(f"Reader isolated must be 'keep' or 'leave out', got {self.isolated!r}")
        if self.isolated != "keep" and self.bonds != "cohesive":
            raise ValueError("Reader isolated= is for bonded solids (bonds='cohesive'): in a granular bed a particle "
                             "touching nothing is an element like the others")
        if self.clumps not in (None, "lumped", "resolved"):
            raise ValueError(f"Reader clumps must be 'lumped' (one temperature per clump) or 'resolved' (one per "
                             f"member), got {self.clumps!r}")

    def scene_options(self) -> dict:
        """The scene reader's keyword arguments."""
        return dict(bonds=self.bonds, mask=self.mask, geometry_every=self.geometry_every,
                    move_tolerance=self.move_tolerance, full_read_every=self.full_read_every,
                    bond_check=self.bond_check, sweep_calls=self.sweep_calls, skin=self.skin,
                    clumps=self.clumps if self.clumps is not None or self.bonds != "contacts" else "lumped",
                    isolated=self.isolated)


@dataclass(frozen=True)
class Output:
    """What an engine writes, besides its own attributes.

    Parameters
    ----------
    history : str, optional
        CSV file written row by row, one row per call (iter, time, R_eq, ``V_<name>`` and
        ``I_<name>`` per electrode, power, energies, temperatures, ...); ``engine.history`` holds
        the rows too.
    history_mode : {'w', 'a', 'x'}
        Replace the file (saying so), append to it, or refuse an existing one.
    write_back : str or None
        Body attribute that receives each element's potential [V] (default ``'potential'``;
        None: none). Temperatures always go to ``b.state.temp``.
    plot : bool
        Also feed ``yade.plot.addData`` with each history row.
    measure : (str, str), optional
        The two electrodes of ``equivalent_resistance`` (default: the first two).
    """

    history: Optional[str] = None
    history_mode: str = "w"
    write_back: Optional[str] = "potential"
    plot: bool = False
    measure: Optional[Tuple[str, str]] = None


@dataclass(frozen=True)
class Electrode(PotentialOrCurrent):
    """An electrode: where the current enters or leaves, and its potential or current.

    Give one place and one value.

    Parameters
    ----------
    name : str
    select : selector, optional
        An element layer (paper 000's electrodes: a perfect conductor through the selected
        elements' centres): a YADE predicate (``pack.inAlignedBox(...)``), body ids, a boolean
        mask, ``dict(mask=m)`` (bodies with ``b.mask & m``) or ``f(pos, radius) -> mask``.
    surface : surface, optional
        A surface of the container (``rod.face('top')``, a ``Plane``, a region): the electrode
        is that surface, joined to each touching element through its half cell.
    wall : int or list of int, optional
        Body id(s) of a ``Wall``, ``Box`` or facet mesh of a granular bed: each particle
        touching it conducts through its contact.
    potential : float, optional
        Fixed potential [V].
    current : float, optional
        Imposed current fed into the packing [A].
    """

    name: str
    select: Any = None
    surface: Any = None
    wall: Any = None
    potential: Optional[float] = None
    current: Optional[float] = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise BoundaryConditionError(f"electrode names must be non-empty strings, got {self.name!r}")
        if (self.select is not None) + (self.surface is not None) + (self.wall is not None) != 1:
            raise BoundaryConditionError(f"Electrode {self.name!r}: give select= (an element layer), surface= (a "
                                         "surface of the container) or wall= (a wall of a granular bed), one of them")
        self.check_value()
        if self.wall is not None:
            object.__setattr__(self, "wall", tuple(_body_ids(f"Electrode {self.name!r}: wall", self.wall)))

@dataclass(frozen=True)
class Wall:
    """A wall of a granular bed for the heat: isothermal or adiabatic.

    Parameters
    ----------
    name : str
    bodies : int or list of int
        Body ids of a ``Wall``, ``Box`` or facet mesh (``geom.facetCylinder`` is one wall).
    temperature : float, optional
        Isothermal at this temperature [K]: each touching sphere exchanges heat through its
        contact (the plane contact radius of its overlap). None: adiabatic.
    conductivity : float, optional
        The wall's thermal conductivity [W/(m K)] (default the particles'); a contact takes the
        harmonic mean of the two.
    """

    name: str
    bodies: Any
    temperature: Optional[float] = None
    conductivity: Optional[float] = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise BoundaryConditionError(f"wall names must be non-empty strings, got {self.name!r}")
        object.__setattr__(self, "bodies", tuple(_body_ids(f"Wall {self.name!r}: bodies", self.bodies)))

    def spec(self) -> dict:
        """The wall as the engine's internal ``dict(bodies=, temperature=, conductivity=)``."""
        return dict(bodies=list(self.bodies), temperature=self.temperature, conductivity=self.conductivity)


@dataclass(frozen=True)
class Materials:
    """Spheres of several YADE materials.

    Parameters
    ----------
    default : Material
        The properties of every sphere whose YADE material is not in ``by_yade_material``.
    by_yade_material : dict
        YADE material (its ``label`` in ``O.materials``, or its index) -> :class:`Material`
        with the properties that differ (the others are the default's).
    """

    default: Material
    by_yade_material: Mapping[Union[str, int], Material] = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.default, Material):
            raise MaterialError(f"Materials(default=...) must be a Material, got {self.default!r}")
        if not isinstance(self.by_yade_material, Mapping):
            raise MaterialError("Materials(by_yade_material=...) must be a dict YADE material (label or index in "
                                f"O.materials) -> Material(...), got {self.by_yade_material!r}")
        for key, m in dict(self.by_yade_material).items():
            if not isinstance(m, Material):
                raise MaterialError(f"Materials by_yade_material[{key!r}] must be a Material, got {m!r}")

    def table(self, allowed, engine: str = "this engine") -> dict:
        """{YADE material: {property: value}} of the ``allowed`` properties; MaterialError for a
        property the engine does not take."""
        out = {}
        for key, m in dict(self.by_yade_material).items():
            given = [k for k in ("resistivity", "density", "specific_heat", "conductivity") if getattr(m, k) is not None]
            extra = [k for k in given if k not in allowed]
            if extra:
                raise MaterialError(f"by_yade_material[{key!r}]: {engine} takes no {extra} (it takes {list(allowed)})")
            if not given:
                raise MaterialError(f"by_yade_material[{key!r}]: give the properties that differ, "
                                    f"e.g. Material({allowed[0]}=...)")
            out[key] = {k: float(getattr(m, k)) for k in given}
        return out


@dataclass(frozen=True)
class InitialTemperature:
    """Starting temperatures.

    Parameters
    ----------
    value : float
        Every element's starting temperature [K], and that of elements added later.
    by_id : dict, optional
        body id -> K for chosen elements (e.g. a hot and a cold half of a bed). Ignored when
        the engine resumes a saved run (the temperatures are then the bodies' ``b.state.temp``).
    """

    value: float
    by_id: Optional[Mapping[int, float]] = None

    def __post_init__(self):
        object.__setattr__(self, "value", real_number("InitialTemperature value (K)", self.value))


# =========================================================================================
# the option objects -> the engines' internal settings
# =========================================================================================
def _material(material, allowed, engine: str):
    """(the default Material, {YADE material: {property: value}} or None) of ``material=``."""
    if isinstance(material, Materials):
        default, table = material.default, material.table(allowed, engine)
    elif isinstance(material, Material):
        default, table = material, None
    else:
        raise MaterialError(f"{engine}: material= must be a Material(...) (yade_electro.Material), or "
                            f"Materials(default=..., by_yade_material=...) for spheres of several YADE materials; got "
                            f"{material!r}")
    for name in allowed:
        v = getattr(default, name)
        if v is not None and np.ndim(v) != 0:
            raise MaterialError(f"{engine}: {name} must be one value; give spheres of several YADE materials their "
                                "own values with Materials(default=..., by_yade_material={label: Material(...)})")
    return default, table


def _scalar(v):
    return None if v is None else float(v)


def _sorted_boundaries(boundaries, engine: str, allowed: tuple) -> dict:
    """The boundary objects grouped by type, with their names checked for clashes."""
    if hasattr(boundaries, "name"):           # one boundary object, not a list
        boundaries = [boundaries]
    if isinstance(boundaries, Mapping):
        raise BoundaryConditionError(f"{engine}: boundaries= is a list, e.g. [Electrode('top', surface=rod.face('top'), "
                                     "potential=1.0), Electrode('bottom', ...)]; a dict of electrodes is the old form")
    groups = {cls: [] for cls in allowed}
    names = []
    for b in boundaries or ():
        cls = next((c for c in allowed if isinstance(b, c)), None)
        if cls is None:
            said = ", ".join("FixedTemperature, HeatFlux, Convection, HeatSource (or FixedValue, Injection, Robin, "
                             "Source)" if c.__name__ == "Condition" else c.__name__ for c in allowed)
            raise TypeError(f"{engine}: boundaries= takes {said} objects, got {b!r}")
        groups[cls].append(b)
        names.append(b.name)
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise BoundaryConditionError(f"{engine}: boundary names must be unique, {dup} given more than once")
    return groups


def _common(law: Law, reader, output, engine: str) -> dict:
    if not isinstance(reader, Reader):
        raise TypeError(f"{engine}: reader= must be a Reader(...), got {reader!r}")
    if not isinstance(output, Output):
        raise TypeError(f"{engine}: output= must be an Output(...), got {output!r}")
    return dict(law=None if law.name == "auto" else law.name, law_params=dict(law.params), container=law.container,
                measure=output.measure, history=output.history, history_mode=output.history_mode,
                write_back=output.write_back, plot=output.plot, reselect=reader.reselect,
                **reader.scene_options())


def electrical_settings(material, boundaries, law, reader, output) -> dict:
    """The ElectricalEngine's internal settings from its option objects."""
    engine = "ElectricalEngine"
    mat, table = _material(material, ("resistivity",), engine)
    if mat.resistivity is None:
        raise MaterialError(f"{engine} needs material=Material(resistivity=...) (ohm m)")
    if reader.overlap:
        raise ValueError("Reader(overlap=True) is for heat-only engines in a granular bed; leave it False here")
    groups = _sorted_boundaries(boundaries, engine, (Electrode,))
    if not groups[Electrode]:
        raise BoundaryConditionError(f"{engine}: give boundaries=[Electrode(...), Electrode(...)] (at least one)")
    law = Law.of(law)
    out = _common(law, reader, output, engine)
    if law.volume_fraction is not None:
        raise ValueError(f"{engine}: Law(volume_fraction=...) sets heat capacities; it is for the heat engines")
    out.update(resistivity=_scalar(mat.resistivity), electrodes=list(groups[Electrode]), materials=table)
    return out


#: the roles of the boundary vocabulary a heat engine takes (besides Electrode and Wall)
HEAT_ROLES = ("fixed", "injection", "robin", "source")


def absolute_temperature(what: str, value) -> float:
    """``value`` as a float, refused (ValueError) unless finite and > 0: the engines work in
    kelvin (b.state.temp is YADE's absolute temperature)."""
    T = real_number(what, value)
    if not T > 0.0:
        raise ValueError(f"{what}: {T!r} is not an absolute temperature; the engines work in kelvin, > 0 K (20 degC is "
                         "293.15 K)")
    return T


def _check_kelvin(engine: str, conditions, walls) -> None:
    """The temperatures the heat conditions and walls give, each > 0 K (:func:`absolute_temperature`)."""
    for c in conditions:
        for role, unit in getattr(c, "UNITS", {}).items():
            field = getattr(c, "FIELDS", {}).get(role, role)
            v = getattr(c, field, None)
            if unit == "K" and v is not None and not callable(v):
                for x in np.ravel(np.asarray(v, dtype=object)):
                    absolute_temperature(f"{engine}: {c.KIND} {c.name!r} {field}", x)
    for w in walls:
        if w.temperature is not None:
            absolute_temperature(f"{engine}: Wall {w.name!r} temperature", w.temperature)


def thermal_settings(material, boundaries, temperature, law, integrator, reader, output, engine: str) -> dict:
    """The heat engines' internal settings from their option objects."""
    from ..network.boundary import Condition
    from ..physics.integrator import MODEL_OPTIONS, Integrator
    groups = _sorted_boundaries(boundaries, engine, (Electrode, Wall, Condition))
    for c in groups[Condition]:
        if c.ROLE not in HEAT_ROLES:
            raise TypeError(f"{engine}: {c!r} is not a heat condition; give FixedTemperature, HeatFlux, Convection, "
                            "HeatSource (or FixedValue, Injection, Robin, Source), and electrodes as Electrode(...)")
    electrodes = groups[Electrode]
    allowed = ("density", "specific_heat", "conductivity") + (("resistivity",) if electrodes else ())
    mat, table = _material(material, allowed, engine)
    if electrodes and mat.resistivity is None:
        raise MaterialError(f"{engine}: electrodes need material=Material(resistivity=...) (ohm m)")
    if not electrodes and mat.beta != 0.0:
        raise MaterialError(f"{engine}: beta (rho_e(T)) needs electrodes")
    for name in ("density", "specific_heat", "conductivity"):
        if getattr(mat, name) is None:
            raise MaterialError(f"{engine} needs material=Material(density=..., specific_heat=..., conductivity=...) "
                                f"(kg/m^3, J/(kg K), W/(m K)); {name} is missing")
    if isinstance(temperature, InitialTemperature):
        T, by_id = temperature.value, temperature.by_id
    elif temperature is None:
        raise ValueError(f"{engine}: give the starting temperature= (K), or InitialTemperature(K, by_id={{id: K}})")
    else:
        T, by_id = real_number(f"{engine}: temperature (K)", temperature), None
    absolute_temperature(f"{engine}: temperature", T)
    for k, v in (by_id.items() if hasattr(by_id, "items") else ()):     # (not a dict: refused when the engine is built)
        absolute_temperature(f"{engine}: initial_temperature[{k}] (InitialTemperature by_id)", v)
    _check_kelvin(engine, groups[Condition], groups[Wall])
    if not isinstance(integrator, Integrator):
        raise TypeError(f"{engine}: integrator= must be an Integrator(...), got {integrator!r}")
    base = Integrator()
    extra = {k: getattr(integrator, k) for k in MODEL_OPTIONS if getattr(integrator, k) != getattr(base, k)}
    if mat.beta != 0.0:
        extra["reference_temperature"] = float(mat.reference_temperature)
    law = Law.of(law)
    if law.volume_fraction is not None:
        extra["volume_fraction"] = law.volume_fraction
    out = _common(law, reader, output, engine)
    out.update(resistivity=_scalar(mat.resistivity) if electrodes else None,
               electrodes=list(electrodes) or None,
               density=_scalar(mat.density), specific_heat=_scalar(mat.specific_heat),
               conductivity=_scalar(mat.conductivity), temperature=T, initial_temperature=by_id,
               beta=float(mat.beta), eta=float(integrator.eta), theta=integrator.theta,
               heat_conditions=list(groups[Condition]),
               thermal_dt=integrator.dt, time_scale=integrator.time_scale, steady=integrator.steady,
               thermal_solver=integrator.solver, coupled_options=extra or None,
               walls={w.name: w.spec() for w in groups[Wall]} or None, materials=table, overlap=reader.overlap)
    return out


def electrodes_from_dict(electrodes: Mapping[str, Mapping]) -> list:
    """``[Electrode(name, **spec), ...]`` from the dict form ``{name: dict(select=|surface=|wall=,
    potential=|current=)}``."""
    if not isinstance(electrodes, Mapping):
        raise BoundaryConditionError(f"electrodes_from_dict takes {{name: dict(...)}}, got {electrodes!r}")
    out = []
    for name, spec in electrodes.items():
        if not isinstance(spec, Mapping):
            raise BoundaryConditionError(f"electrode {name!r}: give a dict(select=... or surface=..., "
                                         "potential=...|current=...)")
        unknown = sorted(set(spec) - {"select", "surface", "wall", "potential", "current"})
        if unknown:
            raise BoundaryConditionError(f"electrode {name!r}: unknown key(s) {unknown}; give select=, surface= or "
                                         "wall=, and potential= (V) or current= (A)")
        out.append(Electrode(name, **spec))
    return out


def walls_from_dict(walls: Mapping[str, Mapping]) -> list:
    """``[Wall(name, **spec), ...]`` from the dict form ``{name: dict(bodies=, temperature=,
    conductivity=)}``."""
    if not isinstance(walls, Mapping):
        raise BoundaryConditionError(f"walls_from_dict takes {{name: dict(bodies=...)}}, got {walls!r}")
    out = []
    for name, spec in walls.items():
        if not isinstance(spec, Mapping):
            raise BoundaryConditionError(f"wall {name!r}: give dict(bodies=ids, temperature=K or None)")
        unknown = sorted(set(spec) - {"bodies", "temperature", "conductivity"})
        if unknown:
            raise BoundaryConditionError(f"wall {name!r}: unknown key(s) {unknown}; give bodies=, temperature=, "
                                         "conductivity=")
        out.append(Wall(name, **spec))
    return out
