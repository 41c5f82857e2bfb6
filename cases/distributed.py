"""Distributed runs against serial ones: the same engine, ``solver='petsc'`` on every rank of
``mpiexec``, each rank holding only its share of the network.

Cases (each prints its figures; rank 0 ends with one JSON line of them all):

``rod``
    A bonded rod (rod_resistance's, R = 1 mm, L = 5 mm, 304L, rho_e(T) with beta = 1e-3 1/K)
    with the 'voronoi' law (each rank tessellates only its region: its slab and a halo),
    Joule-heated between its end layers (1 V), the bottom layer held at 293 K, backward Euler,
    ``--calls`` calls. Plain mpiexec: every rank runs the whole (static) scene and owns a slab.
    The serial engine (``solver='direct'``) runs on the same scene, call by call, beside the
    distributed one: the reference is exact and on the same geometry.
``rod-continuum``
    The same with the continuum law.
``rod-surface-voronoi``, ``rod-surface-continuum``
    The rod with its electrodes and conditions on the container's faces: the top face fed
    ROD_I and 0.5 W of heat, the bottom face grounded and held at 293 K, convection on the
    side, a source in the whole rod (each rank chooses the faces' elements on its region).
``rod-cells``
    The ``rod`` case with ``Integrator(joule_sharing='cells')``, the default under 'voronoi'
    (``rod`` itself keeps 'edges'): each element's Joule heat from the field over its cell
    (gradients from the ghosts' potentials, the total summed over the ranks; the electrode
    layers' elements and their neighbours, ghosts included, keep the links' share).
``bed``
    A granular bed settling on a floor under gravity (hexagonal lattice, contact law), Joule-
    heated between its two ends, one end at 293 K, Crank-Nicolson, serial engine beside the
    distributed one as for the rod (plain mpiexec: the mechanics are every rank's).
``pin``
    The pin torsion test (pin_torsion's pin, rig and kept calibration), twisted 20 times the
    paper's rate until 0.12 rad or separation, with its continuum-law engine (end element
    layers) serial and distributed side by side: bonds break, each rank's share loses edges,
    the solves are rebuilt collectively. Plain mpiexec.
``pin-voronoi``
    The same with the 'voronoi' law and crack facets (the broken bonds' facets cut the faces
    across them), on the same end layers (surface electrodes are not distributed).
``walls``
    The bed with its floor as a wall electrode (grounded) and an isothermal wall (280 K), the
    left end fed WALLS_I: the links of the spheres on the floor, against serial.
``heat``
    Heat only on the bed (HeatEngine, made distributed by ``Integrator(solver='petsc')``): one end
    at 350 K, convection to 280 K at the other, forward Euler with sub-steps. Plain mpiexec.
``mpy``
    The same bed inside YADE's MPI mode (``yade.mpy``, ``mp.mpirun``): rank 0 is YADE's master
    (owns no sphere), the other ranks its workers (x slabs). yade.mpy's mechanics do not follow
    the serial ones (measured: 3.1e-5 m apart after 1,000 steps with no engine at all), so the
    reference here is a serial solve on the geometry the workers had at the last call: R_eq,
    electrode currents and potentials.
``mpy-walls``
    The same with walls_engine's electrodes: the floor, a body of yade.mpy's master, is the
    wall electrode and the isothermal wall every worker joins its spheres to. One of ``mpy``
    and ``mpy-walls`` per run (yade.mpy splits the scene for good).

``max_rel_diff``: the worst over the cases of R_eq, electrode currents, potentials (over the
applied voltage) and temperature rises (over the largest rise).

Memory (``--cases mem --mem N``): a bed of about N spheres (``--mem 114000``: 215,407), the
engine's own growth of the peak RSS (VmHWM reset before it is built; PETSc's and MPI's
libraries, about 80 MB per process, loaded before and reported apart) in a serial process (started
by rank 0) and on every rank of the distributed run: ``mem_ratio`` = the largest rank's growth over
the serial one. ``process_peak_ratio`` compares whole processes (in plain mpiexec every rank
holds YADE's whole scene).

Run
---
    mpiexec --allow-run-as-root --oversubscribe -n 3 yade-electro -n -x cases/distributed.py
    mpiexec ... -n 2 yade-electro -n -x cases/distributed.py --quick     # small, for the tests
    mpiexec ... -n 3 yade-electro -n -x cases/distributed.py --cases mem --mem 200000

Ends with one JSON line (rank 0).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("distributed.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("distributed.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from yade_electro.yade.runtime import import_yade  # noqa: E402

T0 = 293.0


def _comm():
    from yade_electro.solvers.partitioned import mpi_comm
    return mpi_comm()


def _say(msg):
    if _comm().Get_rank() == 0:
        sys.stderr.write(f"[distributed] {msg}\n")
        sys.stderr.flush()


def _worst(comm, x) -> float:
    return max(comm.allgather(float(x)))


def _pair(make, calls, steps_per_call, electrical=True, walls=(), fed=None):
    """Run the serial engine (solver='direct') and the distributed one (solver='petsc') side by
    side on the scene, ``calls`` calls; returns both and the worst relative differences (with
    ``walls``: also of their contact counts, heat flows and heats; ``fed``: the electrode fed a
    current, the first: the voltage it takes is compared and is the scale of the potentials)."""
    yade = import_yade()
    O = yade.Omega()
    ser, dis = make("direct", "ser"), make("petsc", "dis")
    O.engines = O.engines + [ser.runner, dis.runner]
    t = time.perf_counter()
    O.run(calls * steps_per_call, True)
    wall = time.perf_counter() - t
    comm = _comm()
    model = dis._distributed.model
    own = model.share.owned_ids
    d_R, d_I, d_phi = 0.0, 0.0, 0.0
    d_W, d_V, contacts = 0.0, 0.0, []
    for rs, rd in zip(ser.history.rows, dis.history.rows):
        if fed:
            d_V = max(d_V, abs(rd["voltage"] - rs["voltage"]) / abs(rs["voltage"]))
        if electrical:
            d_R = max(d_R, abs(rd["R_eq"] - rs["R_eq"]) / abs(rs["R_eq"]))
            d_I = max(d_I, abs(rd["joule_power"] - rs["joule_power"]) / abs(rs["joule_power"]))
        for w in walls:
            contacts.append([rs[f"wall_contacts:{w}"], rd[f"wall_contacts:{w}"]])
            for key in (f"wall_power:{w}", f"wall_heat:{w}"):
                d_W = max(d_W, abs(rd[key] - rs[key]) / max(abs(rs[key]), 1e-300))
    Ts = ser.temperature_by_id
    Td = model.temperatures_by_id()
    rise = max(abs(v - T0) for v in Ts.values())
    d_T = _worst(comm, max((abs(Td[i] - Ts[i]) for i in own.tolist()), default=0.0)) / rise
    if electrical:
        phi_s = ser.potential_by_id
        d_phi = _worst(comm, max((abs(p - phi_s[i]) for i, p in zip(own.tolist(), model.potential.tolist())),
                                 default=0.0)) / (abs(dis.history.rows[-1]["voltage"]) if fed else 1.0)
    O.engines = [e for e in O.engines if getattr(e, "label", "") not in ("ser", "dis")]
    out = {"calls": len(dis.history.rows), "R_eq": dis.history.rows[-1].get("R_eq"), "R_rel_diff": d_R,
           "joule_rel_diff": d_I, "potential_diff_over_V": d_phi, "T_rise_K": rise, "T_rel_diff": d_T,
           "owned": int(own.size), "elements": int(dis.history.rows[-1]["elements"]), "wall_s": wall,
           "solve_iterations": dis.history.rows[-1].get("solve_iterations"),
           "substeps_serial_distributed": [ser.history.rows[-1].get("n_substeps"), dis.history.rows[-1].get("n_substeps")]}
    if fed:
        out.update({"fed_potential_rel_diff": d_V, f"V_{fed}": dis.history.rows[-1][f"V_{fed}"],
                    f"I_{fed}": dis.history.rows[-1][f"I_{fed}"]})
    if walls:
        last = dis.history.rows[-1]
        out.update({"wall_rel_diff": d_W, "wall_contacts_serial_distributed": contacts[-1],
                    "wall_contacts_equal": all(a == b for a, b in contacts),
                    "wall_power_W": {w: last[f"wall_power:{w}"] for w in walls},
                    "wall_heat_J": {w: last[f"wall_heat:{w}"] for w in walls},
                    "electrode_currents_A": {k[2:]: v for k, v in last.items() if k.startswith("I_")}})
    out["max_rel_diff"] = max(d_R, d_I, d_phi, d_T, d_W, d_V)
    return out


# -- the rod --------------------------------------------------------------------------------
#: the current fed into the rod's top face in the surface variant [A]
ROD_I = 200.0


def rod_case(n=3000, calls=5, cache_dir=None, law="voronoi", surface=False, sharing="edges"):
    """``surface``: the electrodes and conditions on the container's faces instead of element
    layers: the top face fed ROD_I and 0.5 W of heat, the bottom face grounded and held at
    293 K, the side cooled by convection (each element joined through its half cell, the faces
    chosen on each rank's region), and a source of 1e8 W/m^3 in the whole rod. ``sharing``: the
    Joule heat's ``Integrator(joule_sharing=...)``."""
    from rod_resistance import RHO_304L, build_rod
    from yade_electro.geometry.shapes import as_shape
    from yade_electro.yade import (Convection, ElectroThermalEngine, Electrode, FixedTemperature, HeatFlux,
                                   HeatSource, Integrator, Law, Material, Output)
    spec = build_rod(n=n, seed=1, cache_dir=cache_dir)
    ids = spec["ids"]
    mat = Material(resistivity=RHO_304L, density=7900.0, specific_heat=500.0, conductivity=16.0, beta=1e-3,
                   reference_temperature=T0)
    rod = as_shape(spec["container"])
    if surface:
        boundaries = [Electrode("top", surface=rod.face("top"), current=ROD_I),
                      Electrode("bottom", surface=rod.face("bottom"), potential=0.0),
                      FixedTemperature("cold", surface=rod.face("bottom"), temperature=T0),
                      Convection("air", surface=rod.face("side"), h=2000.0, t_inf=T0),
                      HeatFlux("lamp", surface=rod.face("top"), power=0.5), HeatSource("core", density=1e8)]
    else:
        boundaries = [Electrode("top", select=ids[spec["top"]], potential=1.0),
                      Electrode("bottom", select=ids[spec["bottom"]], potential=0.0),
                      FixedTemperature("cold", nodes=ids[spec["bottom"]], temperature=T0)]

    def make(solver, label):
        return ElectroThermalEngine(
            material=mat, law=Law(law, container=rod) if law == "voronoi" or surface else law,
            boundaries=boundaries, temperature=T0,
            integrator=Integrator(theta="backward-euler", dt=1e-3, joule_sharing=sharing),
            solver=solver, iterPeriod=1, label=label, output=Output(write_back=None))
    return _pair(make, calls, 1, fed="top" if surface else None)


# -- the pin ---------------------------------------------------------------------------------
def pin_case(n=1000, rate_factor=20.0, every=100, theta_max=0.12, cache_dir=None, law="continuum"):
    """The pin torsion test (pin_torsion's pin and rig, its kept calibration for ``n``), twisted
    ``rate_factor`` times faster than the paper until ``theta_max`` or separation, with an
    engine on the end element layers serial and distributed side by side: bonds break, the
    share's edges change, the solves are rebuilt on every rank. ``law``: 'continuum' (the
    paper's), or 'voronoi' with crack='facets' (the broken bonds' facets cut the faces)."""
    import math
    from pin_torsion import RAMP_ANGLE, RESISTIVITY, build_pin, load_calibration, paper_rate, pin_electrodes
    from yade_electro.yade import ElectricalEngine, Law, Material, Output, Reader, electrodes_from_dict
    yade = import_yade()
    O = yade.Omega()
    cal = load_calibration(n, 1, cache_dir=cache_dir, progress=_say)
    rate = paper_rate() * rate_factor
    pin = build_pin(n, 1, cal["young"], cal["strength"], rate=rate, ramp_time=2 * RAMP_ANGLE / rate,
                    cache_dir=cache_dir)
    electrodes, _ = pin_electrodes(pin, "continuum")
    # positions read at every call: a reader refreshes them lazily (every few calls, or when a
    # bond it holds breaks), and a rank holds a region, not the scene, so the two engines would
    # otherwise see positions of different calls (measured: up to 8e-4 in R_eq at one call)
    chosen = Law("voronoi", container=pin["container"], crack="facets") if law == "voronoi" else law

    def make(solver, label):
        return ElectricalEngine(material=Material(resistivity=RESISTIVITY), boundaries=electrodes_from_dict(electrodes),
                                law=chosen, reader=Reader(bond_check="flags", geometry_every=1, move_tolerance=0.0),
                                output=Output(write_back=None),
                                solver=solver, iterPeriod=every, label=label)
    ser, dis = make("direct", "pin_ser"), make("petsc", "pin_dis")
    O.engines = O.engines + [ser.runner, dis.runner]
    rig = pin["rig"]
    t = time.perf_counter()
    while rig.theta < theta_max and math.isfinite(ser.equivalent_resistance if len(ser.history) else 0.0):
        O.run(10 * every, True)
    wall = time.perf_counter() - t
    comm = _comm()
    d_R, finite = 0.0, 0
    for rs, rd in zip(ser.history.rows, dis.history.rows):
        if math.isfinite(rs["R_eq"]) != math.isfinite(rd["R_eq"]):
            d_R = math.inf                          # one separated, the other not
        elif math.isfinite(rs["R_eq"]):
            d_R = max(d_R, abs(rd["R_eq"] - rs["R_eq"]) / abs(rs["R_eq"]))
            finite += 1
    last_finite = [r for r in ser.history.rows if math.isfinite(r["R_eq"])]
    own = dis.body_ids
    phi_s = ser.potential_by_id
    d_phi = _worst(comm, max((abs(p - phi_s[i]) for i, p in zip(own.tolist(), dis.potential.tolist())), default=0.0))
    O.engines = [e for e in O.engines if getattr(e, "label", "") not in ("pin_ser", "pin_dis")]
    rig.remove()
    pin["strength_check"].remove()
    R0 = ser.history.rows[0]["R_eq"]
    return {"calls": len(dis.history.rows), "theta": float(rig.theta), "R_eq_first": R0,
            "R_ratio_last_finite": last_finite[-1]["R_eq"] / R0 if last_finite else None,
            "law": law, "separated": not math.isfinite(ser.history.rows[-1]["R_eq"]), "R_rel_diff": d_R,
            "potential_diff_over_V": d_phi, "compared_calls": finite, "elements": int(len(pin["ids"])),
            "wall_s": wall, "max_rel_diff": max(d_R, d_phi)}


# -- the bed --------------------------------------------------------------------------------
def build_bed(n_target=200, r=1e-3, gravity=-9.81, young=1e6):
    """A hexagonal lattice of spheres (about ``n_target``, a 4:1:1 box) on a floor box, in
    YADE's scene (reset first). Returns (ids, x) of the spheres."""
    yade = import_yade()
    from yade import pack, utils
    O = yade.Omega()
    O.reset()
    W = yade
    side = (n_target / 16.0 / 0.74 * (4.0 / 3.0) * np.pi) ** (1.0 / 3.0) * r * 2.0
    O.materials.append(W.FrictMat(young=young, poisson=0.3, frictionAngle=0.4, density=2600, label="bed"))
    O.bodies.append(pack.regularHexa(pack.inAlignedBox((0, 0, 0), (4 * side, side, side)), radius=r, gap=0.0,
                                     material="bed"))
    pos = np.array([tuple(b.state.pos) for b in O.bodies])
    lo, hi = pos.min(axis=0) - r, pos.max(axis=0) + r
    O.bodies.append(utils.box(center=(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2] - 0.5 * r + 1e-9),
                          extents=(0.5 * (hi[0] - lo[0]) + r, 0.5 * (hi[1] - lo[1]) + r, 0.5 * r), fixed=True,
                          material="bed"))
    O.engines = [W.ForceResetter(), W.InsertionSortCollider([W.Bo1_Sphere_Aabb(), W.Bo1_Box_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom(), W.Ig2_Box_Sphere_ScGeom()],
                                   [W.Ip2_FrictMat_FrictMat_FrictPhys()], [W.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 W.NewtonIntegrator(gravity=(0, 0, gravity), damping=0.4)]
    O.dt = 0.3 * utils.PWaveTimeStep()
    spheres = [b for b in O.bodies if isinstance(b.shape, W.Sphere)]
    return np.array([b.id for b in spheres]), np.array([b.state.pos[0] for b in spheres]), r


#: the bed's resistivity [ohm m]
BED_RHO = 1e-5


def bed_engine(ids, x, r, solver, label, period, beta=2e-3):
    from yade_electro.yade import (ElectroThermalEngine, Electrode, FixedTemperature, Integrator, Material, Output,
                                   Reader)
    mat = Material(resistivity=BED_RHO, density=2600.0, specific_heat=800.0, conductivity=2.0, beta=beta,
                   reference_temperature=T0)
    left, right = ids[x < x.min() + r], ids[x > x.max() - r]
    return ElectroThermalEngine(
        material=mat, law="contact", reader=Reader(bonds="contacts"),
        boundaries=[Electrode("left", select=left, potential=1.0), Electrode("right", select=right, potential=0.0),
                    FixedTemperature("cold", nodes=left, temperature=T0)],
        temperature=T0, integrator=Integrator(theta="crank-nicolson", dt=0.5), solver=solver, iterPeriod=period,
        label=label, output=Output(write_back=None))


def floor_id() -> int:
    """The body id of the bed's floor (build_bed's box)."""
    yade = import_yade()
    return next(b.id for b in yade.Omega().bodies if isinstance(b.shape, yade.Box))


#: the current fed into the left end [A], out through the floor electrode (walls_engine): a
#: rise of tens of K
WALLS_I = 3.0


def walls_engine(ids, x, r, solver, label, period, beta=2e-3):
    """The bed with its floor as a wall electrode (0 V) and as an isothermal wall (280 K), the
    left end layer fed WALLS_I (its potential found by the solve): the current and the heat
    leave through the spheres' floor contacts."""
    from yade_electro.yade import ElectroThermalEngine, Electrode, Integrator, Material, Output, Reader, Wall
    mat = Material(resistivity=BED_RHO, density=2600.0, specific_heat=800.0, conductivity=2.0, beta=beta,
                   reference_temperature=T0)
    floor = floor_id()
    return ElectroThermalEngine(
        material=mat, law="contact", reader=Reader(bonds="contacts"),
        boundaries=[Electrode("left", select=ids[x < x.min() + r], current=WALLS_I),
                    Electrode("floor", wall=[floor], potential=0.0),
                    Wall("floor_heat", bodies=[floor], temperature=280.0, conductivity=20.0)],
        temperature=T0, integrator=Integrator(theta="crank-nicolson", dt=0.5), solver=solver, iterPeriod=period,
        label=label, output=Output(write_back=None))


def walls_case(n=200, calls=8, period=100):
    """The settling bed on its floor, the floor an electrode and an isothermal wall, the left end
    fed a current (walls_engine), serial beside distributed; also the left end's potential, the
    floor's contacts, heat flow and heat against serial."""
    ids, x, r = build_bed(n)
    return _pair(lambda solver, label: walls_engine(ids, x, r, solver, label, period), calls, period,
                 walls=("floor_heat",), fed="left")


def heat_case(n=200, calls=8, period=100):
    """Heat only on the bed (HeatEngine): one end held at 350 K, convection to 280 K at the other,
    forward Euler with sub-steps (the call's step is far above the stable one), a flux of
    2 kW/m^2 on the exposed area of the spheres of the middle third and 20 mW from a source in
    the last quarter, shared by volume; serial beside distributed (``Integrator(solver='petsc')``
    makes a heat engine distributed)."""
    from yade_electro.yade import (Convection, FixedTemperature, HeatEngine, HeatFlux, HeatSource, Integrator,
                                   Material, Reader)
    ids, x, r = build_bed(n)
    mat = Material(density=2600.0, specific_heat=800.0, conductivity=2.0)
    left, right = ids[x < x.min() + r], ids[x > x.max() - r]
    span = x.max() - x.min()
    middle = ids[(x > x.min() + span / 3) & (x < x.max() - span / 3)]
    last = ids[x > x.max() - span / 4]

    def make(solver, label):
        return HeatEngine(material=mat, law="contact", reader=Reader(bonds="contacts"),
                          boundaries=[FixedTemperature("hot", nodes=left, temperature=350.0),
                                      Convection("air", nodes=right, h=50.0, t_inf=280.0, area=3e-6),
                                      HeatFlux("lamp", nodes=middle, flux=200.0),
                                      HeatSource("core", nodes=last, power=0.002)],
                          temperature=T0, integrator=Integrator(theta="explicit", dt=200.0, solver=solver),
                          iterPeriod=period, label=label)
    return _pair(make, calls, period, electrical=False)


def bed_case(n=200, calls=8, period=100):
    ids, x, r = build_bed(n)
    return _pair(lambda solver, label: bed_engine(ids, x, r, solver, label, period), calls, period)


# -- the bed in yade.mpy --------------------------------------------------------------------
def mpy_case(n=200, calls=8, period=100, walls=False):
    """The bed under yade.mpy (rho_e constant, so that the last call's potential depends on its
    geometry only); the reference is a serial solve on the geometry the workers had at the last
    call, gathered on rank 0 for this check only. ``walls``: the floor (the master's body) is
    the second electrode and an isothermal wall (walls_engine); the reference joins the spheres
    that overlap it to an electrode node."""
    from yade import mpy as mp
    from yade_electro.core.graph import ContactGraph
    from yade_electro.core.materials import electrical_conductance
    from yade_electro.laws.factors import make_law
    from yade_electro.network.conduction import ConductionProblem
    from yade_electro.network.kirchhoff import Electrode as Terminal
    yade = import_yade()
    O = yade.Omega()
    ids, x, r = build_bed(n)
    workers = mp.numThreads - 1
    order = np.argsort(x, kind="stable")
    for k, i in enumerate(order):            # x slabs; bodies outside subdomain 0 do not move in a serial run
        O.bodies[int(ids[i])].subdomain = 1 + k * workers // len(order)
    floor = O.bodies[floor_id()]
    floor_top = float(floor.state.pos[2] + floor.shape.extents[2])
    eng = (walls_engine if walls else bed_engine)(ids, x, r, "petsc", "mpy", period, beta=0.0)
    O.engines = O.engines + [eng.runner]
    t = time.perf_counter()
    mp.mpirun(calls * period, workers + 1, withMerge=False)
    wall = time.perf_counter() - t
    share = eng._distributed.share
    mine = None
    if share is not None and share.graph is not None:
        k = share.n_owned
        mine = (share.owned_ids, share.graph.pos[:k], share.graph.radius[:k], eng._distributed.model.potential)
    got = [g for g in mp.comm.gather(mine, root=0) or [] if g is not None]
    if mp.rank != 0:
        return None
    gid = np.concatenate([g[0] for g in got])
    pos, rad, phi = (np.concatenate([g[k] for g in got]) for k in (1, 2, 3))
    from scipy.spatial import cKDTree
    pairs = cKDTree(pos).query_pairs(2.0 * rad.max(), output_type="ndarray")
    d = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    graph = ContactGraph(pos, rad, pairs[d < rad[pairs[:, 0]] + rad[pairs[:, 1]]], ids=gid)
    law = make_law("contact")
    edges, c = graph.edges, electrical_conductance(law.factor(graph, graph.edges), BED_RHO, graph.edges)
    left = np.flatnonzero(np.isin(gid, ids[x < x.min() + r]))
    second = "floor" if walls else "right"
    if walls:                                # the floor: an electrode node joined to the spheres on it
        overlap = rad - (pos[:, 2] - floor_top)
        on = np.flatnonzero(overlap > 0)
        edges = np.concatenate([edges, np.column_stack([on, np.full(on.size, graph.n_nodes)])])
        c = np.concatenate([c, law.wall_factor(rad[on], overlap[on]) / BED_RHO])
        terminals = [Terminal("left", left, current=WALLS_I), Terminal("floor", [graph.n_nodes], potential=0.0)]
    else:
        right = np.flatnonzero(np.isin(gid, ids[x > x.max() - r]))
        terminals = [Terminal("left", left, potential=1.0), Terminal("right", right, potential=0.0)]
    sol = ConductionProblem(graph.n_nodes + int(walls), edges, c, terminals, solver="direct").solve()
    row = eng.history.rows[-1]
    R = sol.equivalent_resistance("left", second)
    d_R = abs(row["R_eq"] - R) / R
    d_I = max(abs(row[f"I_{k}"] - sol.electrode_current[k]) / abs(sol.electrode_current[k]) for k in ("left", second))
    volts = abs(sol.electrode_potential["left"] - sol.electrode_potential[second])
    d_phi = float(np.max(np.abs(phi - sol.potential[:graph.n_nodes]))) / volts
    out = {"workers": workers, "calls": len(eng.history.rows), "R_eq": row["R_eq"], "R_rel_diff": d_R,
           "current_rel_diff": d_I, "potential_diff_over_V": d_phi, "elements": int(row["elements"]),
           "wall_s": wall, "max_rel_diff": max(d_R, d_I, d_phi)}
    if walls:
        out.update({"floor_contacts": int(on.size), "floor_contacts_engine": row["wall_contacts:floor_heat"],
                    "floor_heat_J": row["wall_heat:floor_heat"]})
        if on.size != row["wall_contacts:floor_heat"]:
            out["max_rel_diff"] = float("inf")    # the workers did not see the master's floor
    return out


# -- memory -------------------------------------------------------------------------------
def _vm(key: str) -> float:
    """A line of /proc/self/status in bytes (VmRSS, VmHWM)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return float(line.split()[1]) * 1024.0
    return float("nan")


def _reset_peak():
    """Make VmHWM the current RSS (Linux >= 4.0: writing 5 to clear_refs)."""
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")


def engine_memory(n: int, solver: str, calls: int = 2) -> dict:
    """Peak RSS growth [bytes] of an engine built on a bed of about ``n`` touching spheres (no
    mechanics: the scene is read as it is) and called ``calls`` times."""
    yade = import_yade()
    O = yade.Omega()
    ids, x, r = build_bed(n, gravity=0.0)
    for b in O.bodies:                       # touching neighbours: grow the spheres by 1 %
        if isinstance(b.shape, yade.Sphere):
            b.shape.radius *= 1.01
    import gc
    lib = _vm("VmRSS")
    if solver.startswith("petsc"):           # PETSc's and MPI's libraries: loaded once per process
        from yade_electro.solvers.petsc import import_petsc
        import_petsc()
    lib = _vm("VmRSS") - lib
    gc.collect()
    _reset_peak()
    rss0 = _vm("VmRSS")
    t = time.perf_counter()
    eng = bed_engine(ids, x, r * 1.01, solver, "mem_" + solver.replace("-", "_"), 1)
    for _ in range(calls):
        eng.step()
    wall = time.perf_counter() - t
    row = eng.history.rows[-1]
    return {"spheres": int(ids.size), "growth_bytes": _vm("VmHWM") - rss0, "rss_before_bytes": rss0,
            "libraries_bytes": lib, "process_peak_bytes": _vm("VmHWM"),
            "wall_s": wall, "R_eq": row["R_eq"], "solver": solver}


def mem_case(n: int) -> dict:
    """The serial engine in a process of its own (started by rank 0, without the MPI
    environment), then the distributed one on every rank; mem_ratio over the serial growth."""
    import subprocess
    comm = _comm()
    serial = None
    if comm.Get_rank() == 0:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX", "PMI_", "OPAL_"))}
        exe = [sys.executable] if "yade" in os.path.basename(sys.executable) else ["yade-electro"]
        cmd = exe + ["-n", "-x", os.path.abspath(_SCRIPT), "--cases", "mem-serial", "--mem", str(n)]
        res = subprocess.run(cmd, env=env, capture_output=True, text=True, stdin=subprocess.DEVNULL)
        rows = [json.loads(line) for line in res.stdout.splitlines() if line.startswith('{"mem_serial"')]
        if res.returncode != 0 or not rows:
            raise RuntimeError(f"the serial memory run failed: {res.stderr[-2000:]}")
        serial = rows[0]["mem_serial"]
    comm.Barrier()
    mine = engine_memory(n, "petsc")
    every = comm.gather(mine, root=0)
    if comm.Get_rank() != 0:
        return {}
    worst = max(e["growth_bytes"] for e in every)
    return {"spheres": mine["spheres"], "serial_growth_MB": serial["growth_bytes"] / 1e6,
            "rank_growth_MB": [e["growth_bytes"] / 1e6 for e in every],
            "mem_ratio": worst / serial["growth_bytes"],
            "libraries_MB": max(e["libraries_bytes"] for e in every) / 1e6,
            "process_peak_ratio": max(e["process_peak_bytes"] for e in every) / serial["process_peak_bytes"],
            "R_rel_diff": abs(mine["R_eq"] - serial["R_eq"]) / serial["R_eq"],
            "serial_wall_s": serial["wall_s"], "rank_wall_s": [e["wall_s"] for e in every],
            "note": "mem_ratio: the engines' own growth of the peak RSS, PETSc's libraries loaded before (libraries_MB); "
                    "process_peak_ratio: whole processes, YADE's scene (every rank's in plain mpiexec) included"}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", default="rod,rod-continuum,rod-surface-voronoi,rod-surface-continuum,rod-cells,pin,"
                                       "pin-voronoi,bed,walls,heat,mpy",
                    help="comma-separated: rod, rod-continuum, rod-surface-voronoi, rod-surface-continuum, rod-cells, "
                         "pin, "
                         "pin-voronoi, bed, walls, heat, mpy or mpy-walls (one of them, last), mem")
    ap.add_argument("--quick", action="store_true", help="small sizes (the CI test)")
    ap.add_argument("--n-rod", type=int, default=3000)
    ap.add_argument("--n-bed", type=int, default=400)
    ap.add_argument("--n-pin", type=int, default=5000)
    ap.add_argument("--mem", type=int, default=200000, help="spheres of the memory case")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    cases = [c for c in args.cases.split(",") if c]
    n_rod, n_bed = (1000, 200) if args.quick else (args.n_rod, args.n_bed)
    comm = _comm()
    out = {"ranks": comm.Get_size()}
    if "heat" in cases:
        _say(f"heat: about {n_bed} spheres")
        out["heat"] = heat_case(n_bed)
    if "mem-serial" in cases:               # the serial half of the memory case, in its own process
        print(json.dumps({"mem_serial": engine_memory(args.mem, "cg-deflated")}), flush=True)
        return None
    if "rod" in cases:
        _say(f"rod: {n_rod} elements")
        out["rod"] = rod_case(n_rod, cache_dir=args.cache_dir)
    if "rod-continuum" in cases:
        _say(f"rod, continuum law: {n_rod} elements")
        out["rod_continuum"] = rod_case(n_rod, cache_dir=args.cache_dir, law="continuum")
    for law in ("voronoi", "continuum"):
        if f"rod-surface-{law}" in cases:
            _say(f"rod, {law} law, electrodes and conditions on its faces: {n_rod} elements")
            out[f"rod_surface_{law}"] = rod_case(n_rod, cache_dir=args.cache_dir, law=law, surface=True)
    if "rod-cells" in cases:
        _say(f"rod, Joule heat shared by cells: {n_rod} elements")
        out["rod_cells"] = rod_case(n_rod, cache_dir=args.cache_dir, sharing="cells")
    if "pin" in cases:
        n_pin = 1000 if args.quick else args.n_pin
        _say(f"pin: {n_pin} elements")
        out["pin"] = pin_case(n_pin, cache_dir=args.cache_dir)
    if "pin-voronoi" in cases:
        n_pin = 1000 if args.quick else args.n_pin
        _say(f"pin, voronoi law with crack facets: {n_pin} elements")
        out["pin_voronoi"] = pin_case(n_pin, cache_dir=args.cache_dir, law="voronoi")
    if "bed" in cases:
        _say(f"bed: about {n_bed} spheres")
        out["bed"] = bed_case(n_bed)
    if "walls" in cases:
        _say(f"bed on a floor electrode and isothermal wall: about {n_bed} spheres")
        out["walls"] = walls_case(n_bed)
    if "mem" in cases:
        _say(f"memory: about {args.mem} spheres")
        out["mem"] = mem_case(args.mem)
        if comm.Get_rank() == 0:
            out["mem_ratio"] = out["mem"]["mem_ratio"]
    for case in ("mpy", "mpy-walls"):        # last: yade.mpy splits the scene for good (one of them)
        if case in cases:
            _say(f"{case}: about {n_bed} spheres")
            res = mpy_case(n_bed, walls=case == "mpy-walls")
            if res is not None:
                out[case.replace("-", "_")] = res
            break
    if comm.Get_rank() == 0:
        diffs = [v["max_rel_diff"] for v in out.values() if isinstance(v, dict) and "max_rel_diff" in v]
        out["max_rel_diff"] = max(diffs) if diffs else None
        out["workers"] = {"plain_mpiexec": comm.Get_size(), "yade_mpy": comm.Get_size() - 1}
        print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
