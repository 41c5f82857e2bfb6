"""Heat conduction through contacts in LIGGGHTS (``fix heat/gran/conduction``): a deck from
the ``heat_conduction`` template for a packing, its run, and its temperatures and contacts
back as DataFrames.

What LIGGGHTS 3.8.0 computes (``fix_heat_gran_conduction.cpp``): for every pair with
d < r_i + r_j, the contact area A = pi a^2 of the lens of the two spheres (with
``area_correction``, the overlap is first scaled by (Y*/Y*_orig)^(1/p), p = 3/2 for Hertz),
a conductance h_c = 4 k_i k_j / (k_i + k_j) sqrt(A) = 2 sqrt(pi) k a for equal k, and an
explicit Euler step of T_i += dt sum_j h_c (T_j - T_i) / (m_i c_i) every time step. This is
yade-electro's ``liggghts`` law; paper 002's ``contact`` law is 2 k a, smaller by sqrt(pi).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Dict, Optional, Sequence

from .datafile import ParticleData, format_data
from .deck import GranularMaterial, material_commands, pair_local_columns, render_deck, temperature_commands, \
    wall_commands, wall_files
from .dumps import read_dump
from .runner import LiggghtsRun, run_deck

__all__ = ["HEAT_PAIR_KEYWORDS", "HeatDeck", "heat_conduction_deck", "HeatRunResult", "run_heat_conduction"]

#: what the heat deck's contact dump holds
HEAT_PAIR_KEYWORDS = ("pos", "id", "contactArea", "delta", "heatFlux")


@dataclass(frozen=True)
class HeatDeck:
    """A rendered heat deck: ``deck`` text, ``files`` (name -> text) it reads, the dump file
    names, the time step [s] and the number of steps."""

    deck: str
    files: dict
    atom_dump: str
    pair_dump: str
    timestep: float
    steps: int
    dump_every: int


def heat_conduction_deck(data: ParticleData, materials: Sequence[GranularMaterial], temperature: float,
                         timestep: float, steps: int, dump_every: int,
                         initial_temperature: Optional[Dict[int, float]] = None, walls=(),
                         integrate: bool = False, gravity: bool = False, area_correction: bool = False,
                         contact_model: str = "hertz", neighbor_skin: Optional[float] = None,
                         thermo_every: Optional[int] = None) -> HeatDeck:
    """The deck of a heat-conduction run on ``data``.

    Parameters
    ----------
    data : ParticleData
        The particles (written as ``particles.data``); atom type k is ``materials[k - 1]``.
    materials : sequence of GranularMaterial
        With conductivity and specific_heat.
    temperature : float
        Initial temperature of every particle [K].
    timestep : float
        LIGGGHTS' time step [s] (the heat's explicit Euler step too).
    steps, dump_every : int
        Steps to run; a snapshot of temperatures and contacts every ``dump_every`` steps
        (step 0 included).
    initial_temperature : dict atom id -> K, optional
        Particles that start elsewhere.
    walls : PlaneWall / CylinderWall / MeshWall, optional
        With ``temperature`` for isothermal walls.
    integrate : bool
        Move the particles (``fix nve/sphere``); False: a static packing, contacts fixed.
    gravity : bool
        Gravity along -z (with ``integrate``).
    area_correction : bool
        LIGGGHTS' ``area_correction`` (needs ``young_original`` on every material).
    contact_model : str
        ``hertz`` or ``hooke``.
    neighbor_skin : float, optional
        Neighbour-list skin [m] (default: the largest radius).
    """
    mats = list(materials)
    if data.n_types > len(mats):
        raise ValueError(f"the particles have {data.n_types} atom types but {len(mats)} materials were given")
    if area_correction and not all(m.young_original is not None for m in mats):
        raise ValueError("area_correction needs young_original (the real Young's modulus) on every material")
    steps, dump_every = int(steps), int(dump_every)
    if steps < 1 or dump_every < 1:
        raise ValueError(f"steps and dump_every must be >= 1, got {steps}, {dump_every}")
    if not timestep > 0:
        raise ValueError(f"timestep must be > 0 (s), got {timestep!r}")
    if not (float(temperature) > 0 and float(temperature) < float("inf")):
        raise ValueError(f"temperature must be finite and > 0 (K), got {temperature!r}")
    if contact_model not in ("hertz", "hooke"):
        raise ValueError(f"contact_model must be 'hertz' or 'hooke', got {contact_model!r}")
    init = dict(initial_temperature or {})
    unknown = sorted(set(init) - set(data.ids.tolist()))
    if unknown:
        raise ValueError(f"initial_temperature names atom ids not in the data: {unknown[:5]}")
    files = {"particles.data": format_data(data)}
    files["temperatures.set"] = temperature_commands(list(init), list(init.values()))
    files.update(wall_files(walls))
    cols = pair_local_columns(HEAT_PAIR_KEYWORDS)
    deck = render_deck(
        "heat_conduction", data_file="particles.data",
        neighbor_skin=f"{neighbor_skin if neighbor_skin is not None else float(data.radius.max()):.9g}",
        materials=material_commands(mats, heat=True), contact_model=contact_model, timestep=f"{timestep:.12g}",
        gravity="fix gravity all gravity 9.81 vector 0.0 0.0 -1.0" if gravity else "# no gravity",
        walls=wall_commands(walls, contact_model), initial_temperature=f"{temperature:.12g}",
        area_correction="yes" if area_correction else "no",
        temperatures="include temperatures.set" if init else "# every particle at the initial temperature",
        integration="fix integrate all nve/sphere" if integrate else "# static packing: no time integration",
        pair_keywords=" ".join(HEAT_PAIR_KEYWORDS), dump_every=dump_every, atom_dump="dump.atoms",
        pair_dump="dump.contacts", pair_columns=" ".join(f"c_contacts[{k + 1}]" for k in range(len(cols))),
        thermo_every=thermo_every or max(dump_every, steps // 20), steps=steps)
    return HeatDeck(deck=deck, files=files, atom_dump="dump.atoms", pair_dump="dump.contacts",
                    timestep=float(timestep), steps=steps, dump_every=dump_every)


@dataclass(frozen=True, eq=False)
class HeatRunResult:
    """A heat run: ``temperatures`` {step: DataFrame id, type, radius, x, y, z, Temp [K],
    heat_flux [W]}, ``contacts`` {step: DataFrame of :data:`HEAT_PAIR_KEYWORDS` columns:
    x1..z2, id1, id2, periodic, contact_area [m^2], delta [m], heat_flux [W]}, ``times``
    {step: t [s]} and the :class:`LiggghtsRun`."""

    temperatures: dict
    contacts: dict
    times: dict
    run: LiggghtsRun

    def temperature_table(self):
        """Temperatures [K] as a DataFrame: one row per dump time (index t [s]), one column
        per atom id."""
        import pandas as pd
        rows = {self.times[s]: df.set_index("id")["Temp"] for s, df in sorted(self.temperatures.items())}
        return pd.DataFrame(rows).T.sort_index()


def run_heat_conduction(deck: HeatDeck, workdir, exe=None, timeout: float = 600.0,
                        progress: Optional[float] = 10.0, ranks: int = 1) -> HeatRunResult:
    """Run a :class:`HeatDeck` in ``workdir`` and read its dumps; ``ranks`` MPI processes
    (see :func:`~yade_electro.liggghts.runner.run_deck`)."""
    run = run_deck(deck.deck, workdir, files=deck.files, exe=exe, timeout=timeout, progress=progress,
                   total_steps=deck.steps, ranks=ranks)
    atoms = read_dump(Path(workdir) / deck.atom_dump,
                      columns=["id", "type", "radius", "x", "y", "z", "Temp", "heat_flux"])
    contacts = read_dump(Path(workdir) / deck.pair_dump, columns=pair_local_columns(HEAT_PAIR_KEYWORDS))
    times = {s: s * deck.timestep for s in atoms}
    return HeatRunResult(temperatures=atoms, contacts=contacts, times=times, run=run)
