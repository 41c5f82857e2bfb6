"""Packings made in LIGGGHTS: particles of discrete size classes inserted at random in a
region of a container (``fix insert/pack``), then settled under gravity (``fix nve/sphere``)
until their kinetic energy is small; the ``settle`` template.

The container is a list of walls (:class:`~.deck.PlaneWall`, :class:`~.deck.CylinderWall`,
or an STL :class:`~.deck.MeshWall`); the result is the settled centres and radii
(:class:`SettledPacking`), ready for a YADE scene (``yade_electro.yade.spheres``) or a
LIGGGHTS heat run (:func:`~.heat.heat_conduction_deck`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from .deck import (GranularMaterial, material_commands, primes_from, render_deck, size_class_commands, wall_commands,
                   wall_files)
from .dumps import read_dump_frames
from .runner import LiggghtsRun, run_deck

__all__ = ["CylinderRegion", "BlockRegion", "SettledPacking", "settle_deck", "settle_packing", "INSERT_TIME",
           "KE_THRESHOLD"]

#: defaults of :func:`settle_deck` (and so of :func:`settle_packing`): the time [s] the insertion
#: runs before the settling chunks, and the kinetic energy per particle [J] below which it stops
INSERT_TIME = 0.1
KE_THRESHOLD = 1e-9


@dataclass(frozen=True)
class CylinderRegion:
    """Insertion region: a cylinder along z of ``radius`` [m] through ``center`` (x, y),
    between ``z_low`` and ``z_high`` [m]."""

    radius: float
    z_low: float
    z_high: float
    center: Tuple[float, float] = (0.0, 0.0)

    def command(self) -> str:
        return (f"region insert_region cylinder z {self.center[0]:.12g} {self.center[1]:.12g} {self.radius:.12g} "
                f"{self.z_low:.12g} {self.z_high:.12g} units box")

    @property
    def volume(self) -> float:
        return np.pi * self.radius ** 2 * (self.z_high - self.z_low)


@dataclass(frozen=True)
class BlockRegion:
    """Insertion region: an axis-aligned box from ``lo`` to ``hi`` (x, y, z) [m]."""

    lo: Tuple[float, float, float]
    hi: Tuple[float, float, float]

    def command(self) -> str:
        b = " ".join(f"{lo:.12g} {hi:.12g}" for lo, hi in zip(self.lo, self.hi))
        return f"region insert_region block {b} units box"

    @property
    def volume(self) -> float:
        return float(np.prod(np.subtract(self.hi, self.lo)))


@dataclass(frozen=True, eq=False)
class SettledPacking:
    """A packing settled in LIGGGHTS: ``ids``, ``types``, ``centers`` (n, 3) [m], ``radii``
    [m], ``masses`` [kg], ``velocities`` (n, 3) [m/s], the ``step`` and time [s] it ended at,
    its kinetic energy per particle [J] and whether that fell below the threshold
    (``settled``), and the :class:`~.runner.LiggghtsRun`."""

    ids: np.ndarray
    types: np.ndarray
    centers: np.ndarray
    radii: np.ndarray
    masses: np.ndarray
    velocities: np.ndarray
    step: int
    time: float
    ke_per_particle: float
    settled: bool
    run: LiggghtsRun

    @property
    def n(self) -> int:
        return int(self.ids.size)


def settle_deck(walls, region, n_particles: int, radii, mass_fractions, material: GranularMaterial,
                box, timestep: float, settle_time: float = 2.0, chunk_time: float = 0.05,
                insert_time: float = INSERT_TIME, ke_threshold: float = KE_THRESHOLD, contact_model: str = "hertz",
                seed: int = 32452843, neighbor_skin: Optional[float] = None) -> str:
    """The ``settle`` deck: ``n_particles`` of the size classes ``radii`` [m] (with their
    ``mass_fractions``) inserted in ``region`` inside the container ``walls``, within the
    simulation ``box`` ((3, 2) [m]), then settled for at most ``settle_time`` [s] in chunks of
    ``chunk_time`` [s] until the kinetic energy per particle is below ``ke_threshold`` [J]."""
    n_particles = int(n_particles)
    if n_particles < 1:
        raise ValueError(f"n_particles must be >= 1, got {n_particles}")
    if not timestep > 0:
        raise ValueError(f"timestep must be > 0 (s), got {timestep!r}")
    box = np.asarray(box, dtype=float)
    if box.shape != (3, 2) or not np.all(box[:, 1] > box[:, 0]):
        raise ValueError(f"box must be [[xlo, xhi], [ylo, yhi], [zlo, zhi]], got {box.tolist()}")
    radii = np.asarray(radii, dtype=float).reshape(-1)
    seeds = primes_from(seed, 3)         # distribution, insertion, first size class
    templates, distribution = size_class_commands(radii, mass_fractions, material.density, seed=seeds[2] + 1)
    chunk = max(1, int(round(chunk_time / timestep)))
    return render_deck(
        "settle", box=" ".join(f"{lo:.12g} {hi:.12g}" for lo, hi in box), n_types=1,
        neighbor_skin=f"{neighbor_skin if neighbor_skin is not None else float(radii.max()):.9g}",
        materials=material_commands([material]), contact_model=contact_model, timestep=f"{timestep:.12g}",
        walls=wall_commands(walls, contact_model), templates=templates, distribution=distribution,
        seed_distribution=seeds[0], seed_insert=seeds[1],
        insert_region=region.command(), n_particles=n_particles, thermo_every=chunk,
        insert_steps=max(1, int(round(insert_time / timestep))), chunk_steps=chunk,
        max_chunks=max(1, int(np.ceil(settle_time / (chunk * timestep)))), ke_threshold=f"{ke_threshold:.6g}",
        final_dump="settled.dump")


def settle_packing(walls, region, n_particles: int, radii, mass_fractions, material: GranularMaterial, box,
                   timestep: float, workdir, settle_time: float = 2.0, exe=None, timeout: float = 1800.0,
                   progress: Optional[float] = 10.0, **deck_options) -> SettledPacking:
    """Make the packing of :func:`settle_deck` in ``workdir`` and read it back. LIGGGHTS may
    insert fewer particles than asked when the region is too small: a warning says so and
    ``n`` is what it inserted."""
    deck = settle_deck(walls, region, n_particles, radii, mass_fractions, material, box, timestep,
                       settle_time=settle_time, **deck_options)
    total = int(round(settle_time / timestep)) + int(round(deck_options.get("insert_time", INSERT_TIME) / timestep))
    run = run_deck(deck, workdir, files=wall_files(walls), exe=exe, timeout=timeout, progress=progress,
                   total_steps=total, total_is_bound=True)
    frame = read_dump_frames(run.workdir / "settled.dump")[-1]
    df = frame.data
    m = re.search(r"YADE_ELECTRO_END step (\d+) ke_per_particle (\S+)", run.text())
    if m is None:
        raise RuntimeError(f"the settle run ended without its end line; see {run.log}")
    step, ke = int(m.group(1)), float(m.group(2))
    threshold = float(deck_options.get("ke_threshold", KE_THRESHOLD))
    if len(df) < n_particles:
        import warnings
        warnings.warn(f"LIGGGHTS inserted {len(df)} of the {n_particles} particles asked for (the insertion region "
                      "is too small for them: make it taller)", stacklevel=2)
    return SettledPacking(ids=df["id"].to_numpy(), types=df["type"].to_numpy(),
                          centers=df[["x", "y", "z"]].to_numpy(), radii=df["radius"].to_numpy(),
                          masses=df["mass"].to_numpy(), velocities=df[["vx", "vy", "vz"]].to_numpy(),
                          step=step, time=step * timestep, ke_per_particle=ke, settled=ke < threshold, run=run)
