"""Current through a pressed column of spheres: the electrical resistance of Hertz contacts
against the force (the chain part of the powder-column case of the granular issue).

A simple-cubic column of N steel spheres (r = 1 mm) along z in YADE, Hertz-Mindlin contacts
(``Ip2_FrictMat_FrictMat_MindlinPhys``, ``Law2_ScGeom_MindlinPhys_Mindlin``), the bottom sphere
held, the top one pushed down with a force F (``O.forces.setPermF``), every sphere free along
z only (a straight chain). At each F the column is relaxed until every contact carries F to
1e-6, then the electrical engine (``bonds='contacts'``, law ``contact``: g = 2 a, conductance
2 a / rho_e) gives R between the top and bottom spheres.

Exact chain result: N - 1 identical contacts in series, R = (N - 1) rho_e / (2 a) with the
Hertz radius a = (3 F R* / (4 E*))^(1/3), R* = r / 2, E* = E / (2 (1 - nu^2)): log R against
log F has slope -1/3. Both contact-radius models of the law are run: ``hertz`` (a = sqrt(R*
delta), the Hertz radius from the overlap) must give the exact result; ``geometric`` (the lens
of the overlap, about sqrt(2) times larger) gives R about 1/sqrt(2) of it, with a slope that
tends to -1/3 as the overlap vanishes.

The column stands on a plate (a YADE ``Wall``, same steel) that is also an electrode: a third
engine (``R_plate``) measures between the top sphere and the plate (``electrodes={'plate':
dict(wall=plate_id, ...)}``), through the N - 1 sphere-sphere contacts and the sphere-plate
contact, whose Hertz radius is a_w = (3 F r / (4 E*))^(1/3) (R* = r: a sphere on a half-space;
the law's plane radius a = sqrt(r delta)) and whose constriction is again rho_e / (2 a_w) (the
sphere's and the plate's halves, rho_e / (4 a_w) each): R = (N - 1) rho_e / (2 a) + rho_e /
(2 a_w), slope -1/3 as well. Measured: YADE's ``Ip2_FrictMat_FrictMat_MindlinPhys`` gives a
sphere-wall contact the reduced radius r / 2 (as if the wall were a second sphere of the same
radius; ``plate_r_star_over_r`` = F / (4/3 E* delta^(3/2)))^2 / r, from the overlap, is 0.5000),
so its overlap is 2^(1/3) times the Hertz one and R_plate comes out 0.88 % below the Hertz
value; against the contact YADE actually makes (``R_plate_yade``, R* = r / 2) it agrees to
1e-5 %.

The random packing (``--random N``, default 400): N steel spheres (r = 1 mm +- 12.5 %)
placed by ``dense_packing`` in a square box of side 6 d, frictionless side walls, between the
plate and a lid (both ``Wall``s, both electrodes). The lid is free along z only and carries a
permanent force F; there is no gravity, so at equilibrium the plate carries F too. At each F
(ascending, 1 to 100 N) the bed is relaxed until the plate's reaction and the lid's contact
force are F to ``RANDOM_TOL`` and R between lid and plate changes by less than
``RANDOM_R_TOL`` over a chunk of steps (see :func:`relax_random`). There is no closed form.
Two figures are reported:

* ``R_check`` (``R_check_error_pct``): the same network built here from YADE's own contact
  *forces*, a_c = (3 f_c R*_c / (4 E*))^(1/3) between spheres (Hertz) and a_w = sqrt(r delta_w)
  on the walls with delta_w from the force on YADE's wall contact (R* = r / 2, see above),
  conductance 2 a / rho_e, solved with SciPy's sparse LU: the engine reads overlaps, this reads
  forces, and they must agree;
* ``slope_random``: log R against log F. A fixed set of contacts whose forces all scale with F
  gives exactly -1/3; a random packing departs from it because contacts are made as it is
  pressed and the forces redistribute. ``slope_fixed_contacts`` is the slope of the network of
  the contacts present at the smallest F only (their radii at each F): the difference from
  ``slope_random`` is what the new contacts do.

Run
---
    yade-electro -n -x cases/powder_column.py [--n 10] [--random 400]  (--random 0: the column only)

Ends with one JSON line: ``{"case": "powder_column", "slope": ..., "slope_error_pct": ...,
"max_R_error_pct": ..., "slope_random": ..., ...}`` (``slope``: the column, ``hertz`` radius
model).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

import numpy as np

_SCRIPT = __file__ if __file__.endswith("powder_column.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("powder_column.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

RADIUS = 1e-3           # m
YOUNG = 200e9           # Pa
POISSON = 0.3
DENSITY = 7800.0        # kg/m^3
RESISTIVITY = 1e-7      # ohm m
#: a surface film's specific resistance [ohm m^2]: its resistance over a Hertz spot equals the
#: spot's constriction rho_e / (2 a) at about 10 N (a = 32 um)
FILM = 5e-12
FORCES = tuple(np.logspace(0, 2, 7))   # N
MODELS = ("hertz", "geometric")


def effective_modulus(E=YOUNG, nu=POISSON) -> float:
    """E* [Pa] of two identical spheres: E / (2 (1 - nu^2))."""
    return E / (2.0 * (1.0 - nu ** 2))


def hertz_radius(F, r=RADIUS) -> np.ndarray:
    """a = (3 F R* / (4 E*))^(1/3) [m] of two identical spheres pressed by F [N]."""
    return (3.0 * np.asarray(F, float) * (r / 2.0) / (4.0 * effective_modulus())) ** (1.0 / 3.0)


def chain_resistance(F, n, r=RADIUS) -> np.ndarray:
    """R [ohm] of n spheres in a row pressed by F: (n - 1) rho_e / (2 a)."""
    return (n - 1) * RESISTIVITY / (2.0 * hertz_radius(F, r))


def chain_resistance_film(F, n, r=RADIUS, film=FILM) -> np.ndarray:
    """R [ohm] of the chain with a film on every contact (Holm): (n - 1) (rho_e / (2 a) +
    film / (pi a^2))."""
    a = hertz_radius(F, r)
    return (n - 1) * (RESISTIVITY / (2.0 * a) + film / (np.pi * a * a))


def plate_radius(F, r=RADIUS) -> np.ndarray:
    """Hertz radius [m] of a sphere pressed by F onto a plate of the same material: R* = r."""
    return (3.0 * np.asarray(F, float) * r / (4.0 * effective_modulus())) ** (1.0 / 3.0)


def plate_chain_resistance(F, n, r=RADIUS, r_star=None) -> np.ndarray:
    """R [ohm] from the top sphere to the plate: the chain plus rho_e / (2 a_w), a_w the
    radius a = sqrt(r delta) of the overlap delta that a Hertz contact of reduced radius
    ``r_star`` (default r: a sphere on a half-space) takes under F."""
    r_star = r if r_star is None else r_star
    delta = (3.0 * np.asarray(F, float) / (4.0 * effective_modulus() * np.sqrt(r_star))) ** (2.0 / 3.0)
    return chain_resistance(F, n, r) + RESISTIVITY / (2.0 * np.sqrt(r * delta))


def press(O, ids, F, tol=1e-6, chunk=2000, max_chunks=60):
    """Set the force on the top sphere and relax until every contact carries F to ``tol``;
    returns (contact forces, steps)."""
    O.forces.setPermF(ids[-1], (0, 0, -float(F)))
    steps = 0
    for _ in range(max_chunks):
        O.run(chunk, True)
        steps += chunk
        fn = np.array([abs(i.phys.normalForce[2]) for i in O.interactions if i.isReal])
        if fn.size == len(ids) and np.max(np.abs(fn / F - 1.0)) < tol:
            return fn, steps
    raise RuntimeError(f"the column did not settle under {F} N within {steps} steps "
                       f"(contact forces {fn.tolist()})")


def run(n=10, forces=FORCES, progress=print):
    """The column in YADE; returns the figures."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import utils
    from yade import wrapper as W
    from yade_electro.yade import ElectricalEngine, Electrode, Law, Material, Output, Reader
    O = yade.Omega()
    O.reset()
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=POISSON, density=DENSITY, frictionAngle=0.3))
    gap = 2 * RADIUS * (1 - 1e-7)         # a touch of overlap: the contacts exist from the start
    plate = O.bodies.append(utils.wall(-RADIUS * (1 - 1e-7), axis=2, sense=1, material=mat))
    ids = O.bodies.append([utils.sphere((0, 0, k * gap), RADIUS, material=mat) for k in range(n)])
    for i in ids:
        O.bodies[i].state.blockedDOFs = "xyXYZ"
    O.engines = [W.ForceResetter(), W.InsertionSortCollider([W.Bo1_Sphere_Aabb(), W.Bo1_Wall_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom(), W.Ig2_Wall_Sphere_ScGeom()],
                                   [W.Ip2_FrictMat_FrictMat_MindlinPhys()],
                                   [W.Law2_ScGeom_MindlinPhys_Mindlin()]),
                 W.NewtonIntegrator(damping=0.7)]
    O.dt = 0.3 * utils.PWaveTimeStep()
    O.step()
    engines = {m: ElectricalEngine(
        material=Material(resistivity=RESISTIVITY),
        boundaries=[
            Electrode("top", select=[ids[-1]], potential=1.0),
            Electrode("bottom", select=[ids[0]], potential=0.0)],
        law=Law("contact", radius=m),
        reader=Reader(bonds="contacts", geometry_every=1, move_tolerance=1e-12),
        output=Output(write_back=None),
        iterPeriod=10 ** 9,
        label=f"column_{m}")
               for m in MODELS}
    engines["film"] = ElectricalEngine(
        material=Material(resistivity=RESISTIVITY),
        boundaries=[Electrode("top", select=[ids[-1]], potential=1.0), Electrode("bottom", select=[ids[0]], potential=0.0)],
        law=Law("contact", radius="hertz", film=FILM),
        reader=Reader(bonds="contacts", geometry_every=1, move_tolerance=1e-12),
        output=Output(write_back=None),
        iterPeriod=10 ** 9,
        label="column_film")
    engines["plate"] = ElectricalEngine(
        material=Material(resistivity=RESISTIVITY),
        boundaries=[Electrode("top", select=[ids[-1]], potential=1.0), Electrode("plate", wall=plate, potential=0.0)],
        law=Law("contact", radius="hertz"),
        reader=Reader(bonds="contacts"),
        output=Output(write_back=None),
        iterPeriod=10 ** 9,
        label="column_plate")
    rows = []
    for F in forces:
        fn, steps = press(O, ids, F)
        row = {"F": float(F), "steps": steps, "force_error": float(np.max(np.abs(fn / F - 1.0))),
               "R_exact": float(chain_resistance(F, n)), "R_film_exact": float(chain_resistance_film(F, n))}
        row["a_hertz"] = float(hertz_radius(F))
        row["R_plate_exact"] = float(plate_chain_resistance(F, n))
        # the overlap YADE's Mindlin law gives the sphere-plate contact under F, and the reduced
        # radius it implies: F = 4/3 E* sqrt(R*) delta^(3/2)
        for m, e in engines.items():
            e.step()
            row[f"R_{m}"] = float(e.equivalent_resistance)
            exact = {"plate": row["R_plate_exact"], "film": row["R_film_exact"]}.get(m, row["R_exact"])
            row[f"R_error_pct_{m}"] = 100.0 * (row[f"R_{m}"] / exact - 1.0)
        nodes, dl = engines["plate"].reader.wall_contacts("plate")
        row["plate_overlap"] = float(dl[0])
        row["plate_r_star_over_r"] = float((3 * F / (4 * effective_modulus() * dl[0] ** 1.5)) ** 2 / RADIUS)
        row["R_plate_yade"] = float(plate_chain_resistance(F, n, r_star=row["plate_r_star_over_r"] * RADIUS))
        row["R_error_pct_plate_vs_yade_wall"] = 100.0 * (row["R_plate"] / row["R_plate_yade"] - 1.0)
        rows.append(row)
        progress(f"F = {F:7.3f} N: R hertz {row['R_hertz']:.5e} ohm ({row['R_error_pct_hertz']:+.4f} %), geometric "
                 f"{row['R_geometric']:.5e} ({row['R_error_pct_geometric']:+.2f} %), exact {row['R_exact']:.5e}")
    logF = np.log([r["F"] for r in rows])
    out = {"case": "powder_column", "n": n, "contacts": n - 1, "forces_N": [r["F"] for r in rows]}
    for m in MODELS + ("plate", "film"):
        slope = float(np.polyfit(logF, np.log([r[f"R_{m}"] for r in rows]), 1)[0])
        exact = -1.0 / 3.0 if m != "film" else float(np.polyfit(logF, np.log([r["R_film_exact"] for r in rows]), 1)[0])
        out[f"slope_{m}"] = slope
        out[f"slope_error_pct_{m}"] = 100.0 * (slope / exact - 1.0)
        out[f"max_R_error_pct_{m}"] = float(max(abs(r[f"R_error_pct_{m}"]) for r in rows))
    out["slope_film_exact"] = float(np.polyfit(logF, np.log([r["R_film_exact"] for r in rows]), 1)[0])
    out["slope"], out["slope_error_pct"] = out["slope_hertz"], out["slope_error_pct_hertz"]
    out["max_R_error_pct"] = out["max_R_error_pct_hertz"]
    out["plate_r_star_over_r"] = float(np.mean([r["plate_r_star_over_r"] for r in rows]))
    out["max_R_error_pct_plate_vs_yade_wall"] = float(max(abs(r["R_error_pct_plate_vs_yade_wall"]) for r in rows))
    out["rows"] = rows
    for e in engines.values():
        e.remove()
    return out


RANDOM_N = 400                          # spheres of the random packing
RANDOM_FORCES = tuple(np.logspace(0, 2, 5))   # N on the lid
RANDOM_TOL = 1e-3                       # relative force balance of the relaxed bed
RANDOM_R_TOL = 1e-4                     # relative change of R over a chunk of steps, relaxed


def build_random(n=RANDOM_N, seed=1, width_d=6.0, height_d=10.0, progress=print):
    """Reset YADE: plate, four frictionless sides, a lid free along z, and ``n`` steel spheres
    placed densely in the box between them (the project's ``dense_packing``: no overlaps, touching
    the walls; radii +- 12.5 %). Returns dict(spheres, plate, lid, sides, width [m])."""
    from yade_electro.geometry.shapes import Box
    from yade_electro.packing import dense_packing
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import utils
    from yade import wrapper as W
    O = yade.Omega()
    O.reset()
    r = RADIUS
    t0 = time.time()
    width = width_d * 2 * r
    h = width / 2
    # the box's height for n spheres of mean radius r at the placement's usual fraction
    height = n * 4.0 / 3.0 * np.pi * r ** 3 / 0.6 / width ** 2
    pk = dense_packing(Box((-h, -h, 0.0), (h, h, height)), n=n, dispersion=0.25, seed=seed)
    progress(f"random packing: {len(pk.radii)} spheres placed at a volume fraction {pk.volume_fraction:.3f} "
             f"({time.time() - t0:.0f} s)")
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=POISSON, density=DENSITY, frictionAngle=0.3))
    smooth = O.materials.append(W.FrictMat(young=YOUNG, poisson=POISSON, density=DENSITY, frictionAngle=0.0))
    plate = O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=mat))
    sides = O.bodies.append([utils.wall(-h, axis=0, sense=1, material=smooth), utils.wall(h, axis=0, sense=-1,
                             material=smooth), utils.wall(-h, axis=1, sense=1, material=smooth),
                             utils.wall(h, axis=1, sense=-1, material=smooth)])
    spheres = O.bodies.append([utils.sphere(tuple(c), float(rad), material=mat)
                               for c, rad in zip(pk.centers, pk.radii)])
    top = max(O.bodies[i].state.pos[2] + O.bodies[i].shape.radius for i in spheres)
    lid = O.bodies.append(utils.wall(top, axis=2, sense=-1, material=mat))
    b = O.bodies[lid]
    b.dynamic = True
    b.state.blockedDOFs = "xyXYZ"
    b.state.mass = sum(O.bodies[i].state.mass for i in spheres)     # the bed's mass
    # viscous contact damping (betan, betas) takes the energy of the rearrangements out; it
    # adds no force at rest, so the relaxed contact forces are Hertz-Mindlin's
    O.engines = [W.ForceResetter(), W.InsertionSortCollider([W.Bo1_Sphere_Aabb(), W.Bo1_Wall_Aabb()]),
                 W.InteractionLoop([W.Ig2_Sphere_Sphere_ScGeom(), W.Ig2_Wall_Sphere_ScGeom()],
                                   [W.Ip2_FrictMat_FrictMat_MindlinPhys(betan=0.5, betas=0.5)],
                                   [W.Law2_ScGeom_MindlinPhys_Mindlin()]),
                 W.NewtonIntegrator(damping=0.7, gravity=(0, 0, 0))]
    O.dt = 0.3 * utils.PWaveTimeStep()
    return {"spheres": list(spheres), "plate": plate, "lid": lid, "sides": list(sides), "width": width}


def _wall_force(O, wall):
    """Sum of the normal forces [N] of the real contacts on ``wall``."""
    f = 0.0
    for i in O.interactions.withBody(wall):
        if i.isReal:
            f += abs(i.phys.normalForce[2])
    return f


def relax_random(O, ids, F, measure, tol=RANDOM_TOL, r_tol=RANDOM_R_TOL, chunk=10_000, max_steps=3_000_000,
                 progress=print):
    """Put F [N] on the lid and run until the plate's reaction and the lid's contacts carry F to
    ``tol`` and the resistance ``measure()`` [ohm] changes by less than ``r_tol`` over a chunk of
    steps. YADE's unbalanced force is no criterion here: the rattlers (spheres held by one or two
    weak contacts, free to drift without gravity) keep it at 2e-3 to 1e-2 (400 and 100 spheres) after the loaded
    skeleton has settled. Returns (steps, R, unbalanced force)."""
    from yade import utils
    O.forces.setPermF(ids["lid"], (0, 0, -float(F)))
    steps, t0, R_prev, R = 0, time.time(), None, None
    while steps < max_steps:
        O.run(chunk, True)
        steps += chunk
        fp, fl = _wall_force(O, ids["plate"]), _wall_force(O, ids["lid"])
        balanced = abs(fp / F - 1) < tol and abs(fl / F - 1) < tol
        R = measure() if balanced else None
        if R is not None and R_prev is not None and abs(R / R_prev - 1) < r_tol:
            return steps, R, float(utils.unbalancedForce())
        R_prev = R
        if steps % (10 * chunk) == 0:
            progress(f"  F = {F:.3g} N: {steps} steps, plate {fp:.5g} N, lid {fl:.5g} N, R {R} "
                     f"({time.time() - t0:.0f} s)")
    raise RuntimeError(f"the random packing did not settle under {F} N within {max_steps} steps "
                       f"(plate {fp:.4g} N, lid {fl:.4g} N, R {R_prev} then {R})")


def _network_from_forces(O, ids, keep=None):
    """The lid-plate resistance [ohm] of the contact network built from YADE's contact forces
    (see the module doc), and the contacts used as (id1, id2) pairs. ``keep``: only these pairs."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    Es = effective_modulus()
    lid, plate = ids["lid"], ids["plate"]
    walls = {lid: 0, plate: 1}
    pairs, g = [], []
    for i in O.interactions:
        if not i.isReal:
            continue
        a, b = i.id1, i.id2
        fn = float(i.phys.normalForce.norm())
        if fn <= 0:
            continue
        if a in walls or b in walls:
            s = b if a in walls else a
            r = O.bodies[s].shape.radius
            # YADE's wall contact: R* = r / 2 (see the module doc), delta from its force
            delta = (3.0 * fn / (4.0 * Es * np.sqrt(r / 2.0))) ** (2.0 / 3.0)
            rad = np.sqrt(r * delta)
        elif not (O.bodies[a].shape.__class__.__name__ == "Sphere" and O.bodies[b].shape.__class__.__name__ == "Sphere"):
            continue
        else:
            r1, r2 = O.bodies[a].shape.radius, O.bodies[b].shape.radius
            rad = (3.0 * fn * (r1 * r2 / (r1 + r2)) / (4.0 * Es)) ** (1.0 / 3.0)
        key = (min(a, b), max(a, b))
        if keep is not None and key not in keep:
            continue
        pairs.append(key)
        g.append(2.0 * rad / RESISTIVITY)
    nodes = sorted({k for p in pairs for k in p} - set(walls))
    index = {b: k + 2 for k, b in enumerate(nodes)}
    index.update(walls)
    n = len(nodes) + 2
    ii = np.array([index[p[0]] for p in pairs])
    jj = np.array([index[p[1]] for p in pairs])
    g = np.array(g)
    L = sp.coo_matrix((np.concatenate([-g, -g, g, g]), (np.concatenate([ii, jj, ii, jj]),
                       np.concatenate([jj, ii, ii, jj]))), shape=(n, n)).tocsr()
    # lid (node 0) at 1 V, plate (node 1) at 0 V; unknowns: the spheres of their connected part
    from scipy.sparse.csgraph import connected_components
    _, lab = connected_components(L, directed=False)
    live = np.flatnonzero(lab == lab[0])
    live = live[live >= 2]
    if lab[0] != lab[1] or live.size == 0:
        return float("inf"), set(pairs)
    Luu = L[live][:, live].tocsc()
    rhs = -L[live][:, [0]].toarray().ravel()
    phi = spla.splu(Luu).solve(rhs)
    current = float(L[0, 0] * 1.0 + L[0][:, live] @ phi)
    return 1.0 / current, set(pairs)


def run_random(n=RANDOM_N, forces=RANDOM_FORCES, seed=1, progress=print):
    """The random packing pressed between plate and lid; returns the figures."""
    from yade_electro.yade.runtime import import_yade
    O = import_yade().Omega()
    from yade_electro.yade import ElectricalEngine, Electrode, Law, Material, Output, Reader
    t0 = time.time()
    ids = build_random(n, seed, progress=progress)
    engine = film_engine = None
    rows, first = [], None

    def measure():
        nonlocal engine, film_engine
        if engine is None:            # made once the bed carries the lid: its contacts exist
            film_engine = ElectricalEngine(
                material=Material(resistivity=RESISTIVITY),
                boundaries=[Electrode("lid", wall=ids["lid"], potential=1.0),
                            Electrode("plate", wall=ids["plate"], potential=0.0)],
                law=Law("contact", radius="hertz", film=FILM),
                reader=Reader(bonds="contacts", geometry_every=1, move_tolerance=1e-12),
                output=Output(write_back=None), iterPeriod=10 ** 9, label="random_column_film")
            engine = ElectricalEngine(
                material=Material(resistivity=RESISTIVITY),
                boundaries=[
                    Electrode("lid", wall=ids["lid"], potential=1.0),
                    Electrode("plate", wall=ids["plate"], potential=0.0)],
                law=Law("contact", radius="hertz"),
                reader=Reader(bonds="contacts", geometry_every=1, move_tolerance=1e-12),
                output=Output(write_back=None),
                iterPeriod=10 ** 9,
                label="random_column")
        engine.step()
        return float(engine.equivalent_resistance)

    for F in forces:
        with warnings.catch_warnings():       # the rattlers (no contact, or none to a wall's part)
            warnings.filterwarnings("ignore", message=".*connected to no electrode")
            steps, R, unbalanced = relax_random(O, ids, F, measure, progress=progress)
        plate_force = _wall_force(O, ids["plate"])
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*connected to no electrode")
            film_engine.step()
        R_film = float(film_engine.equivalent_resistance)
        R_check, pairs = _network_from_forces(O, ids)
        if first is None:
            first = pairs
        R_fixed, _ = _network_from_forces(O, ids, keep=first)
        sph = set(ids["spheres"])
        n_sph = sum(1 for p in pairs if p[0] in sph and p[1] in sph)
        loaded = {b for p in pairs for b in p if b in sph}
        lid_z = float(O.bodies[ids["lid"]].state.pos[2])
        phi = sum(4.0 / 3.0 * np.pi * O.bodies[i].shape.radius ** 3 for i in ids["spheres"]) / (ids["width"] ** 2 * lid_z)
        row = {"F": float(F), "steps": int(steps), "plate_force_error": plate_force / F - 1.0,
               "unbalanced_force": unbalanced, "R": R, "R_check": R_check,
               "R_check_error_pct": 100.0 * (R / R_check - 1.0), "R_fixed_contacts": R_fixed, "R_film": R_film,
               "contacts": len(pairs), "sphere_contacts": n_sph, "loaded_spheres": len(loaded),
               "coordination": 2.0 * n_sph / max(len(loaded), 1), "solid_fraction": phi, "height_m": lid_z,
               "floating_spheres": int(np.sum(engine.solution.floating))}
        rows.append(row)
        progress(f"random packing, F = {F:7.3f} N: R {R:.5e} ohm (network of YADE's forces {R_check:.5e}, "
                 f"{row['R_check_error_pct']:+.2e} %), {len(pairs)} contacts, Z = {row['coordination']:.2f}, "
                 f"phi = {phi:.3f}, {steps} steps ({time.time() - t0:.0f} s)")
    engine.remove()
    film_engine.remove()
    logF = np.log([r["F"] for r in rows])
    slope = float(np.polyfit(logF, np.log([r["R"] for r in rows]), 1)[0])
    slope_fixed = float(np.polyfit(logF, np.log([r["R_fixed_contacts"] for r in rows]), 1)[0])
    slope_film = float(np.polyfit(logF, np.log([r["R_film"] for r in rows]), 1)[0])
    return {"random_n": n, "random_seed": seed, "slope_random": slope, "slope_random_film": slope_film,
            "slope_random_vs_chain_pct": 100.0 * (slope / (-1.0 / 3.0) - 1.0), "slope_fixed_contacts": slope_fixed,
            "max_R_check_error_pct": float(max(abs(r["R_check_error_pct"]) for r in rows)),
            "random_s": round(time.time() - t0, 1), "rows": rows}


def plot(out, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    F = np.array(out["forces_N"])
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ff = np.logspace(np.log10(F[0]), np.log10(F[-1]), 50)
    ax.loglog(ff, chain_resistance(ff, out["n"]), "k-", label="exact chain, Hertz: slope -1/3")
    ax.loglog(ff, plate_chain_resistance(ff, out["n"]), "k--", label="exact, top sphere to plate (Hertz)")
    for m, mk, what in (("hertz", "o", "hertz radius"), ("geometric", "s", "geometric radius"),
                        ("plate", "^", "to the plate, hertz")):
        ax.loglog(F, [r[f"R_{m}"] for r in out["rows"]], mk, label=f"DEM, {what}: slope {out[f'slope_{m}']:.4f}")
    if out.get("random_rows"):
        rr = out["random_rows"]
        ax.loglog([r["F"] for r in rr], [r["R"] for r in rr], "D-", label=f"random packing of {out['random_n']}, lid to "
                  f"plate: slope {out['slope_random']:.4f}")
    ax.set_xlabel("F [N]")
    ax.set_ylabel("R [ohm]")
    ax.set_title(f"{out['n']} spheres in a column" + (", and a random packing" if out.get("random_rows") else ""))
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--random", type=int, default=RANDOM_N, help="spheres of the random packing (0: none)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the random packing's cloud")
    ap.add_argument("--out", default="out/powder_column")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("n", "random"))
    os.makedirs(args.out, exist_ok=True)
    out = run(args.n)
    if args.random:
        rnd = run_random(args.random, seed=args.seed)
        out.update({k: v for k, v in rnd.items() if k != "rows"})
        out["random_rows"] = rnd["rows"]
    out["png"] = plot(out, os.path.join(args.out, f"powder_column_n{args.n}.png"))
    with open(os.path.join(args.out, f"powder_column_n{args.n}.json"), "w") as fh:
        json.dump(out, fh)
    print(f"column of {args.n} spheres: slope {out['slope']:.5f} ({out['slope_error_pct']:+.3f} % from -1/3), R within "
          f"{out['max_R_error_pct']:.4f} % of the exact chain; geometric radius: slope {out['slope_geometric']:.5f}")
    if args.random:
        print(f"random packing of {out['random_n']} spheres: slope {out['slope_random']:.4f} "
              f"(fixed contacts {out['slope_fixed_contacts']:.4f}), engine against the network of YADE's forces "
              f"within {out['max_R_check_error_pct']:.2e} %")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
