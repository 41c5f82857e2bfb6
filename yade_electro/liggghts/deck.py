"""LIGGGHTS input decks rendered from the templates in ``liggghts_templates/`` (package data,
``yade_electro/liggghts/templates``).

Template engine: the standard library's :class:`string.Template` with ``@`` as delimiter
(``@{name}``). Why: no dependency; ``substitute`` refuses a missing value (a deck is never
run with a hole in it); and LIGGGHTS uses ``$`` and ``${name}`` for its own variables, which
stay untouched. The blocks that repeat (one material per atom type, walls, size classes,
initial temperatures) are made by the functions here, so the templates hold no logic.
"""
from __future__ import annotations

import re
import string
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence, Tuple

import numpy as np

__all__ = ["TEMPLATE_DIR", "DeckTemplate", "template_names", "render_deck", "GranularMaterial",
           "PlaneWall", "CylinderWall", "MeshWall", "material_commands", "wall_commands", "wall_files", "safe_file_name",
           "temperature_commands", "size_class_commands", "primes_from", "PAIR_LOCAL_ORDER", "pair_local_columns"]

TEMPLATE_DIR = Path(__file__).with_name("templates")


class DeckTemplate(string.Template):
    """``string.Template`` with ``@{name}`` placeholders (LIGGGHTS keeps ``$``)."""

    delimiter = "@"


def template_names() -> list:
    """Names of the packaged templates (without ``.in``)."""
    return sorted(p.stem for p in TEMPLATE_DIR.glob("*.in"))


def _template_text(template) -> Tuple[str, str]:
    p = Path(str(template))
    if p.suffix == ".in" and p.exists():
        return p.read_text(), str(p)
    packaged = TEMPLATE_DIR / f"{template}.in"
    if packaged.exists():
        return packaged.read_text(), packaged.name
    raise ValueError(f"unknown LIGGGHTS template {template!r}: give one of {template_names()} or the path of "
                     "a .in file")


def render_deck(template, **values) -> str:
    """The deck of ``template`` (a packaged name such as ``'heat_conduction'`` or a path to a
    ``.in`` file) with its ``@{name}`` placeholders replaced by ``values`` (str() of each).
    A placeholder without a value, or a value no placeholder takes, raises ``ValueError``
    naming them."""
    text, where = _template_text(template)
    for k, v in values.items():          # a value must not bring its own commands
        if _SHELL.search(str(v)):
            raise ValueError(f"the value of {k!r} holds a LIGGGHTS 'shell' command: a deck never runs shell commands")
    tpl = DeckTemplate(text)
    wanted = {m.group("named") or m.group("braced") for m in tpl.pattern.finditer(text)} - {None}
    missing, unused = sorted(wanted - set(values)), sorted(set(values) - wanted)
    if missing:
        raise ValueError(f"template {where} needs values for {missing}")
    if unused:
        raise ValueError(f"template {where} has no placeholder for {unused} (it takes {sorted(wanted)})")
    return tpl.substitute({k: str(v) for k, v in values.items()})


_SHELL = re.compile(r"(^|[\n\r&])\s*shell\b", re.IGNORECASE)
_SAFE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.+-]*$")


def safe_file_name(name, what: str = "a file of the run") -> str:
    """``name`` when it is a plain file name that a deck can hold as one word and that stays in
    the work directory (letters, digits, ``_ . + -``; no folder part, no space, no leading
    dot or dash); ValueError otherwise."""
    text = str(name)
    if not _SAFE_NAME.match(text) or text in (".", "..") or ".." in text.split("."):
        raise ValueError(f"{what}: {text!r} is not a plain file name (letters, digits, _ . + -, no folder part or "
                         "space): it goes into the deck as one word and is written inside the work directory")
    return text


def _num(x) -> str:
    return f"{float(x):.12g}"


@dataclass(frozen=True)
class GranularMaterial:
    """One LIGGGHTS atom type's material, SI units.

    young [Pa], poisson [-], restitution [-] (coefficient of restitution), friction [-]
    (Coulomb), density [kg/m^3], conductivity [W/(m K)] and specific_heat [J/(kg K)] (for
    ``fix heat/gran/conduction``; None when no heat runs), young_original [Pa] (the real
    stiffness, for ``area_correction``; None: not corrected).
    """

    young: float
    poisson: float
    density: float
    restitution: float = 0.5
    friction: float = 0.5
    conductivity: Optional[float] = None
    specific_heat: Optional[float] = None
    young_original: Optional[float] = None

    def __post_init__(self):
        for name in ("young", "density"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"GranularMaterial.{name} must be finite and > 0, got {v!r}")
        if not (-1.0 < self.poisson < 0.5):
            raise ValueError(f"GranularMaterial.poisson must be in (-1, 0.5), got {self.poisson!r}")
        if not (0.0 < self.restitution <= 1.0):
            raise ValueError(f"GranularMaterial.restitution must be in (0, 1], got {self.restitution!r}")
        if not self.friction >= 0:
            raise ValueError(f"GranularMaterial.friction must be >= 0, got {self.friction!r}")
        for name in ("conductivity", "specific_heat", "young_original"):
            v = getattr(self, name)
            if v is not None and not (np.isfinite(v) and v > 0):
                raise ValueError(f"GranularMaterial.{name} must be finite and > 0 (or None), got {v!r}")


def material_commands(materials: Sequence[GranularMaterial], heat: bool = False) -> str:
    """The ``fix property/global`` lines of ``materials`` (atom type k+1 is materials[k]);
    pair properties (restitution, friction) are the mean of the two types'. ``heat``: add
    the conductivity and capacity (both required then) and, when every material has it, the
    original Young's modulus of ``area_correction``."""
    mats = list(materials)
    if not mats:
        raise ValueError("give at least one GranularMaterial (one per atom type)")
    n = len(mats)

    def per_type(attr):
        return " ".join(_num(getattr(m, attr)) for m in mats)

    def per_pair(attr):
        vals = [0.5 * (getattr(a, attr) + getattr(b, attr)) for a in mats for b in mats]
        return f"{n} " + " ".join(_num(v) for v in vals)

    lines = [f"fix m_young all property/global youngsModulus peratomtype {per_type('young')}",
             f"fix m_poisson all property/global poissonsRatio peratomtype {per_type('poisson')}",
             f"fix m_restitution all property/global coefficientRestitution peratomtypepair {per_pair('restitution')}",
             f"fix m_friction all property/global coefficientFriction peratomtypepair {per_pair('friction')}"]
    if heat:
        for attr in ("conductivity", "specific_heat"):
            if any(getattr(m, attr) is None for m in mats):
                raise ValueError(f"heat conduction needs the {attr} of every material")
        lines += [f"fix m_conductivity all property/global thermalConductivity peratomtype {per_type('conductivity')}",
                  f"fix m_capacity all property/global thermalCapacity peratomtype {per_type('specific_heat')}"]
        if all(m.young_original is not None for m in mats):
            lines.append(f"fix m_young_orig all property/global youngsModulusOriginal peratomtype "
                         f"{per_type('young_original')}")
    return "\n".join(lines)


@dataclass(frozen=True)
class PlaneWall:
    """A plane wall normal to ``axis`` ('x', 'y' or 'z') at ``position`` [m]; ``temperature``
    [K] makes it isothermal in a heat run (None: adiabatic). ``atom_type``: its material."""

    axis: str
    position: float
    temperature: Optional[float] = None
    atom_type: int = 1

    def __post_init__(self):
        if self.axis not in ("x", "y", "z"):
            raise ValueError(f"PlaneWall.axis must be 'x', 'y' or 'z', got {self.axis!r}")


@dataclass(frozen=True)
class CylinderWall:
    """The lateral surface of a cylinder of ``radius`` [m] along ``axis`` through ``center``
    (the two other coordinates, m)."""

    axis: str
    radius: float
    center: Tuple[float, float] = (0.0, 0.0)
    temperature: Optional[float] = None
    atom_type: int = 1

    def __post_init__(self):
        if self.axis not in ("x", "y", "z"):
            raise ValueError(f"CylinderWall.axis must be 'x', 'y' or 'z', got {self.axis!r}")
        if not self.radius > 0:
            raise ValueError(f"CylinderWall.radius must be > 0 (m), got {self.radius!r}")


@dataclass(frozen=True)
class MeshWall:
    """A triangle mesh from an STL file [m after ``scale``]. The file is copied into the run's
    work directory under a name of the deck's own (:func:`wall_files`), so that any path works
    (spaces, folders) and nothing of it reaches the deck."""

    stl: str
    scale: float = 1.0
    temperature: Optional[float] = None
    atom_type: int = 1


def wall_commands(walls, contact_model: str = "hertz") -> str:
    """``fix wall/gran`` (and ``fix mesh/surface``) lines for ``walls``."""
    lines = []
    for k, w in enumerate(walls or ()):
        temp = f" temperature {_num(w.temperature)}" if w.temperature is not None else ""
        head = f"fix wall{k} all wall/gran model {contact_model} tangential history"
        if isinstance(w, PlaneWall):
            lines.append(f"{head} primitive type {w.atom_type} {w.axis}plane {_num(w.position)}{temp}")
        elif isinstance(w, CylinderWall):
            lines.append(f"{head} primitive type {w.atom_type} {w.axis}cylinder {_num(w.radius)} "
                         f"{_num(w.center[0])} {_num(w.center[1])}{temp}")
        elif isinstance(w, MeshWall):
            if not Path(w.stl).is_file():
                raise FileNotFoundError(f"STL mesh {w.stl!r} of a MeshWall not found")
            lines.append(f"fix mesh{k} all mesh/surface file {_mesh_name(k)} type {int(w.atom_type)} "
                         f"scale {_num(w.scale)}{temp}")
            lines.append(f"{head} mesh n_meshes 1 meshes mesh{k}")
        else:
            raise TypeError(f"walls must be PlaneWall, CylinderWall or MeshWall, got {w!r}")
    return "\n".join(lines) if lines else "# no walls"


def _mesh_name(k: int) -> str:
    return f"wall_mesh{k}.stl"


def wall_files(walls) -> dict:
    """{name in the work directory: path of the STL file} of the walls' meshes (what
    :func:`wall_commands` names), for :func:`~yade_electro.liggghts.runner.run_deck`'s
    ``files``."""
    return {_mesh_name(k): Path(w.stl) for k, w in enumerate(walls or ()) if isinstance(w, MeshWall)}


def temperature_commands(ids, temperatures) -> str:
    """``set atom <id> property/atom Temp <K>`` for each particle given (after ``run 0``)."""
    ids = np.asarray(ids, dtype=np.int64).reshape(-1)
    T = np.asarray(temperatures, dtype=float).reshape(-1)
    if ids.shape != T.shape:
        raise ValueError("give one temperature per atom id")
    if not (np.all(np.isfinite(T)) and np.all(T > 0)):
        raise ValueError("temperatures must be finite and > 0 (K)")
    return "\n".join(f"set atom {i} property/atom Temp {t:.12g}" for i, t in zip(ids.tolist(), T.tolist())) \
        or "# no temperature set"


def size_class_commands(radii, fractions, density, atom_type: int = 1, seed: int = 15485863):
    """The ``fix particletemplate/sphere`` lines of discrete size classes and the
    ``particledistribution/discrete`` argument string (``n id1 f1 id2 f2 ...``, fractions by
    mass, normalised). Seeds must be primes > 10000 (LIGGGHTS), so consecutive primes from
    ``seed`` are used."""
    radii = np.asarray(radii, dtype=float).reshape(-1)
    fr = np.asarray(fractions, dtype=float).reshape(-1)
    if radii.size == 0 or radii.shape != fr.shape:
        raise ValueError("give one mass fraction per size class")
    if not (np.all(radii > 0) and np.all(fr > 0)):
        raise ValueError("radii and mass fractions must be > 0")
    fr = fr / fr.sum()
    seeds = primes_from(seed, radii.size)
    lines = [f"fix size{k} all particletemplate/sphere {s} atom_type {atom_type} density constant {_num(density)} "
             f"radius constant {_num(r)}" for k, (r, s) in enumerate(zip(radii, seeds))]
    dist = f"{radii.size} " + " ".join(f"size{k} {f:.12g}" for k, f in enumerate(fr))
    return "\n".join(lines), dist


def primes_from(start: int, count: int) -> list:
    """The ``count`` primes from ``start`` (at least 10007): LIGGGHTS' seeds."""
    out, p = [], max(int(start), 10007)
    while len(out) < count:
        if p > 1 and all(p % d for d in range(2, int(p ** 0.5) + 1)):
            out.append(p)
        p += 1
    return out


#: ``compute pair/gran/local`` keywords and their columns, in the order LIGGGHTS writes them
#: (heatFlux always last)
PAIR_LOCAL_ORDER = (
    ("pos", ("x1", "y1", "z1", "x2", "y2", "z2")),
    ("vel", ("vx1", "vy1", "vz1", "vx2", "vy2", "vz2")),
    ("id", ("id1", "id2", "periodic")),
    ("force", ("fx", "fy", "fz")),
    ("force_normal", ("fnx", "fny", "fnz")),
    ("force_tangential", ("ftx", "fty", "ftz")),
    ("torque", ("tx", "ty", "tz")),
    ("contactArea", ("contact_area",)),
    ("delta", ("delta",)),
    ("heatFlux", ("heat_flux",)),
)


def pair_local_columns(keywords) -> list:
    """Column names of a ``compute pair/gran/local`` with ``keywords`` (no ``history``)."""
    known = dict(PAIR_LOCAL_ORDER)
    bad = [k for k in keywords if k not in known]
    if bad:
        raise ValueError(f"unknown pair/gran/local keywords {bad}; known: {list(known)}")
    return [c for k, cols in PAIR_LOCAL_ORDER if k in keywords for c in cols]
