"""LIGGGHTS data files of spherical particles (``atom_style granular``), written and read.

The Atoms section of ``atom_style granular`` has one line per particle: ``atom-ID atom-type
diameter density x y z`` (SI: m, kg/m^3, m). The box is the simulation domain LIGGGHTS keeps
its particles in (``boundary f f f``: one that leaves it is lost), so the writer pads the
particles' bounding box unless it is given.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["ParticleData", "particle_data", "format_data", "write_data", "read_data"]


@dataclass(frozen=True, eq=False)
class ParticleData:
    """Spherical particles as LIGGGHTS sees them.

    Attributes
    ----------
    ids : (n,) int array
        Atom ids (>= 1, unique).
    types : (n,) int array
        Atom types (>= 1); a type is a material.
    radius : (n,) float array
        Radii [m] (> 0).
    density : (n,) float array
        Densities [kg/m^3] (> 0).
    positions : (n, 3) float array
        Centres [m].
    box : (3, 2) float array
        ``[[xlo, xhi], [ylo, yhi], [zlo, zhi]]`` [m], containing every particle.
    """

    ids: np.ndarray
    types: np.ndarray
    radius: np.ndarray
    density: np.ndarray
    positions: np.ndarray
    box: np.ndarray

    def __post_init__(self):
        ids = np.asarray(self.ids, dtype=np.int64).reshape(-1)
        n = ids.size
        types = np.asarray(self.types, dtype=np.int64).reshape(-1)
        radius = np.asarray(self.radius, dtype=float).reshape(-1)
        density = np.asarray(self.density, dtype=float).reshape(-1)
        pos = np.asarray(self.positions, dtype=float)
        box = np.asarray(self.box, dtype=float)
        if n == 0:
            raise ValueError("no particles: a LIGGGHTS data file needs at least one atom")
        if pos.shape != (n, 3):
            raise ValueError(f"positions must be ({n}, 3) for {n} ids, got shape {pos.shape}")
        for name, arr in (("types", types), ("radius", radius), ("density", density)):
            if arr.shape != (n,):
                raise ValueError(f"{name} must have one value per particle ({n}), got shape {arr.shape}")
        if ids.min() < 1 or np.unique(ids).size != n:
            raise ValueError("atom ids must be unique and >= 1")
        if types.min() < 1:
            raise ValueError(f"atom types must be >= 1 (LIGGGHTS numbers them from 1), got {types.min()}")
        for name, arr in (("radius (m)", radius), ("density (kg/m^3)", density)):
            if not (np.all(np.isfinite(arr)) and np.all(arr > 0)):
                raise ValueError(f"every {name} must be finite and > 0")
        if not np.all(np.isfinite(pos)):
            raise ValueError("positions must be finite")
        if box.shape != (3, 2) or not np.all(box[:, 1] > box[:, 0]):
            raise ValueError(f"box must be [[xlo, xhi], [ylo, yhi], [zlo, zhi]] with lo < hi, got {box.tolist()}")
        outside = np.any((pos < box[:, 0]) | (pos > box[:, 1]), axis=1)
        if outside.any():
            raise ValueError(f"{int(outside.sum())} particle centres lie outside the box {box.tolist()} "
                             f"(first: id {int(ids[outside][0])}); give a larger box")
        for name, arr in (("ids", ids), ("types", types), ("radius", radius), ("density", density),
                          ("positions", pos), ("box", box)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def n(self) -> int:
        return int(self.ids.size)

    @property
    def n_types(self) -> int:
        return int(self.types.max())

    @property
    def mass(self) -> np.ndarray:
        """Particle masses [kg]."""
        return self.density * 4.0 / 3.0 * np.pi * self.radius ** 3


def particle_data(positions, radius, density, types=1, ids=None, box=None, padding=None) -> ParticleData:
    """:class:`ParticleData` from centres [m], radii [m] and densities [kg/m^3] (scalars or
    one per particle). ``ids`` default 1..n; ``box`` default the particles' bounding box
    padded by ``padding`` (default two largest radii) on every side."""
    pos = np.asarray(positions, dtype=float).reshape(-1, 3)
    n = pos.shape[0]
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (n,)).copy()
    density = np.broadcast_to(np.asarray(density, dtype=float), (n,)).copy()
    types = np.broadcast_to(np.asarray(types, dtype=np.int64), (n,)).copy()
    ids = np.arange(1, n + 1) if ids is None else np.asarray(ids)
    if box is None:
        if n == 0:
            raise ValueError("no particles: a LIGGGHTS data file needs at least one atom")
        pad = 2.0 * float(radius.max()) if padding is None else float(padding)
        lo, hi = (pos - radius[:, None]).min(axis=0) - pad, (pos + radius[:, None]).max(axis=0) + pad
        box = np.stack([lo, hi], axis=1)
    return ParticleData(ids=ids, types=types, radius=radius, density=density, positions=pos, box=box)


def format_data(data: ParticleData, title: str = "written by yade-electro") -> str:
    """The text of ``data`` as a LIGGGHTS data file (``atom_style granular``, SI). Numbers
    have 17 significant digits (the round trip is exact)."""
    box = data.box
    lines = [f"LIGGGHTS data file: {title}", "", f"{data.n} atoms", f"{data.n_types} atom types", ""]
    lines += [f"{box[k, 0]:.17g} {box[k, 1]:.17g} {ax}lo {ax}hi" for k, ax in enumerate("xyz")]
    lines += ["", "Atoms", ""]
    table = np.column_stack([data.ids, data.types, 2.0 * data.radius, data.density, data.positions])
    body = "\n".join(f"{int(r[0])} {int(r[1])} {r[2]:.17g} {r[3]:.17g} {r[4]:.17g} {r[5]:.17g} {r[6]:.17g}"
                     for r in table)
    return "\n".join(lines) + "\n" + body + "\n"


def write_data(path, data: ParticleData, title: str = "written by yade-electro") -> Path:
    """Write ``data`` as a LIGGGHTS data file at ``path`` (see :func:`format_data`); returns
    the path."""
    path = Path(path)
    path.write_text(format_data(data, title))
    return path


def read_data(path) -> ParticleData:
    """Read a LIGGGHTS data file of ``atom_style granular`` (the Atoms section; image flags
    after the coordinates are ignored; other sections such as Velocities are skipped)."""
    path = Path(path)
    try:
        text = path.read_text().splitlines()
    except FileNotFoundError:
        raise FileNotFoundError(f"LIGGGHTS data file {path} not found") from None
    n_atoms, box, rows, k = None, np.zeros((3, 2)), [], 1
    sections = {"Atoms", "Velocities", "Masses", "Bonds", "Pair Coeffs"}
    while k < len(text):
        line = text[k].split("#")[0].strip()
        k += 1
        if not line:
            continue
        words = line.split()
        if line.endswith("atoms") and len(words) == 2:
            try:
                n_atoms = int(words[0])
            except ValueError:
                raise ValueError(f"{path}:{k}: the atom count {words[0]!r} is not a whole number") from None
        elif len(words) == 4 and words[2][1:] == "lo" and words[2][0] in "xyz":
            try:
                lo, hi = float(words[0]), float(words[1])
            except ValueError:
                lo = hi = float("nan")
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise ValueError(f"{path}:{k}: the box bounds {words[0]} {words[1]} along {words[2][0]} are not finite "
                                 "numbers with lo < hi")
            box["xyz".index(words[2][0])] = [lo, hi]
        elif line in sections:
            rows_here = []
            while k < len(text) and not text[k].strip():
                k += 1
            while k < len(text) and text[k].split("#")[0].strip():
                rows_here.append(text[k].split("#")[0].split())
                k += 1
            if line == "Atoms":
                rows = rows_here
    if n_atoms is None or not rows:
        raise ValueError(f"{path} is not a LIGGGHTS data file with an Atoms section")
    if len(rows) != n_atoms:
        raise ValueError(f"{path}: the header says {n_atoms} atoms, the Atoms section has {len(rows)}")
    short = [r for r in rows if len(r) < 7]
    if short:
        raise ValueError(f"{path}: an Atoms line has {len(short[0])} values ({' '.join(short[0])!r}): they need 7, "
                         "id type diameter density x y z (atom_style granular); is the file cut short?")
    try:
        table = np.array([[float(v) for v in r[:7]] for r in rows])
    except ValueError as exc:
        raise ValueError(f"{path}: an Atoms line is not 'id type diameter density x y z' ({exc})") from None
    if table.shape[1] != 7:
        raise ValueError(f"{path}: Atoms lines need 7 columns (id type diameter density x y z, atom_style "
                         "granular)")
    bad = ~np.all(np.isfinite(table), axis=1) | (table[:, 2] <= 0) | (table[:, 3] <= 0)
    if np.any(bad):
        raise ValueError(f"{path}: atoms {table[bad, 0][:5].tolist()} have a value that is not finite, or a diameter or "
                         "density <= 0")
    return ParticleData(ids=table[:, 0].astype(np.int64), types=table[:, 1].astype(np.int64),
                        radius=0.5 * table[:, 2], density=table[:, 3], positions=table[:, 4:7], box=box)
