"""One-call finite-element references for the DEM validation cases (paper 000 section 3,
paper 003's slab), and their mesh-converged values.

Each ``<case>(...)`` function meshes, solves and returns a dict of plain numbers and numpy
arrays; each ``<case>_reference(...)`` repeats it on three meshes (h, h/2, h/4 by default)
and returns the Richardson-extrapolated values with their estimated error
(:mod:`yade_electro.fem.convergence`). A DEM case compares with ``extrapolated`` and
quotes ``gci`` as the uncertainty of the reference.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .closed_forms import adiabatic_joule_temperature, bar_resistance, edge_crack_increment, slab_temperature
from .convergence import converged
from .meshes import (NotchedBarGeometry, PlateGeometry, box_mesh, notched_bar_mesh,
                     plate_mesh, rod_mesh)
from .potential import solve_potential
from .probing import slab_average
from .thermal import joule_heating, transient_conduction

__all__ = ["Material", "STEEL_304L", "rod_resistance", "rod_joule_heating", "plate_potential",
           "notched_bar", "slab_conduction", "rod_reference", "plate_reference",
           "notched_bar_reference"]


@dataclass(frozen=True)
class Material:
    """Electrical and thermal properties (SI).

    Attributes
    ----------
    resistivity : float [ohm m]
    density : float [kg/m^3]
    specific_heat : float [J/kg/K]
    conductivity : float
        Thermal conductivity lambda [W/m/K].
    resistivity_coefficient : float
        beta [1/K] in rho(T) = rho (1 + beta (T - T0)); 0 = constant.
    """

    resistivity: float
    density: float
    specific_heat: float
    conductivity: float
    resistivity_coefficient: float = 0.0

    @property
    def rho_c(self) -> float:
        """Volumetric heat capacity [J/m^3/K]."""
        return self.density * self.specific_heat

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity lambda / (rho c) [m^2/s]."""
        return self.conductivity / self.rho_c


#: Stainless steel 304L as in paper 000.
STEEL_304L = Material(resistivity=0.73e-6, density=7900.0, specific_heat=500.0,
                      conductivity=15.0)

T_ROOM = 293.15  # K


# --------------------------------------------------------------------------- rod
def rod_resistance(radius: float = 1e-3, length: float = 5e-3, h: float | None = None,
                   material: Material = STEEL_304L, order: int = 1, layers: int = 1) -> dict:
    """Equivalent resistance of the rod between its end faces.

    ``layers`` element layers along the axis suffice (the potential is linear in z, which
    P1 represents exactly), so the only discretisation error is the polygonal section.

    Returns
    -------
    dict
        ``R_eq`` [ohm], ``R_theory`` = rho L / (pi R^2), ``relative_error``, ``ndofs``, ``h``.
    """
    h = radius / 4 if h is None else h
    sol = solve_potential(rod_mesh(radius, length, h, layers), material.resistivity,
                          {"end0": 1.0, "end1": 0.0}, order=order)
    r_eq = sol.equivalent_resistance("end0", "end1")
    r_th = bar_resistance(material.resistivity, length, math.pi * radius ** 2)
    return {"R_eq": r_eq, "R_theory": r_th, "relative_error": r_eq / r_th - 1.0,
            "ndofs": sol.ndofs, "h": h}


def rod_joule_heating(radius: float = 1e-3, length: float = 5e-3, voltage: float = 1.0,
                      t_end: float = 0.01, nsteps: int = 10, h: float | None = None,
                      material: Material = STEEL_304L, T0: float = T_ROOM) -> dict:
    """Adiabatic Joule heating of the rod (uniform): FEM against T0 + V^2 t / (rho L^2 rho_c).

    Returns
    -------
    dict
        ``times``, ``T`` (centre), ``T_theory``, ``T_end``, ``relative_error`` (of the rise),
        ``energy_balance_error``.
    """
    h = radius / 3 if h is None else h
    res = joule_heating(rod_mesh(radius, length, h), material.resistivity,
                        material.conductivity, material.rho_c, {"end1": voltage, "end0": 0.0},
                        t_end=t_end, dt=t_end / nsteps, T0=T0, probes=[[0.0, 0.0, length / 2]])
    tth = adiabatic_joule_temperature(res.times, voltage, length, material.resistivity,
                                      material.rho_c, T0)
    t = res.probe_temperatures[:, 0]
    return {"times": res.times, "T": t, "T_theory": tth, "T_end": float(t[-1]),
            "relative_error": float((t[-1] - T0) / (tth[-1] - T0) - 1.0),
            "energy_balance_error": res.energy_balance_error}


# --------------------------------------------------------------------------- plate
def plate_potential(geometry: PlateGeometry = PlateGeometry(), h: float = 1e-3,
                    voltage: float = 1.0, points: dict | None = None, order: int = 2,
                    material: Material = STEEL_304L, layers: int = 1) -> dict:
    """Potential of the plate (bottom grounded, source at ``voltage``) at control points.

    Parameters
    ----------
    points : dict name -> (x, y, z), optional
        Default: ``geometry.control_points()`` (``mid`` and ``corner``).
    layers : int
        Element layers through the thickness (the solution does not depend on z).

    Returns
    -------
    dict
        One entry per point [V], plus ``R_eq`` (source to ground) [ohm] and ``ndofs``.
    """
    points = geometry.control_points() if points is None else points
    sol = solve_potential(plate_mesh(geometry, h, layers=layers), material.resistivity,
                          {"source": voltage, "bottom": 0.0}, order=order)
    x = np.array([points[k] for k in points], dtype=float)
    v = sol.probe(x)
    out = {k: float(val) for k, val in zip(points, v)}
    out["R_eq"] = sol.equivalent_resistance("source", "bottom")
    out["ndofs"] = sol.ndofs
    return out


# --------------------------------------------------------------------------- notched bar
def notched_bar(geometry: NotchedBarGeometry = NotchedBarGeometry(), h: float = 0.25e-3,
                voltage: float = 1.0, current: float | None = None, t_end: float = 0.01,
                nsteps: int | None = None, theta: float = 0.5,
                material: Material = STEEL_304L, T0: float = T_ROOM, order: int = 1,
                nbins: int = 50, notch_refinement: float = 0.5, layers: int = 1) -> dict:
    """Resistance, potential and temperature profiles, and notch temperature of the notched
    bar after adiabatic Joule heating (``voltage`` between x = L and x = 0, or ``current``).

    Parameters
    ----------
    nsteps : int, optional
        Time steps (default: scaled with 1/h, 20 steps at h = 0.25 mm, Crank-Nicolson).
    nbins : int
        Slabs along x for the averaged profiles (compare with DEM elements binned alike).
    layers : int
        Element layers through the thickness (nothing varies with z: the notch goes through
        and heating is adiabatic).

    Returns
    -------
    dict
        ``R_eq`` [ohm] (at T0), ``R_eq_end`` (at t_end, differs only with beta != 0),
        ``T_notch_centre`` / ``T_notch_mean`` (ligament centre / notch-slab mean, t_end) [K],
        ``T_max`` [K], ``x_bins`` (slab centres [m]), ``V_profile`` [V] and ``T_profile`` [K]
        (slab averages at t_end), ``V_centreline`` (potential on the axis at ``x_bins``),
        ``times`` and ``T_notch_history``, ``joule_energy`` [J], ``energy_balance_error``,
        ``ndofs``, ``h``, ``nsteps``.
    """
    g = geometry
    if nsteps is None:
        nsteps = max(10, int(round(20 * 0.25e-3 / h)))
    mesh = notched_bar_mesh(g, h, notch_refinement, layers)
    res = joule_heating(mesh, material.resistivity, material.conductivity, material.rho_c,
                        {"end1": voltage, "end0": 0.0}, t_end=t_end, dt=t_end / nsteps,
                        theta=theta, T0=T0, beta=material.resistivity_coefficient,
                        current=current, probes=[g.notch_centre], order=order)
    edges = np.linspace(0.0, g.length, nbins + 1)
    xc = 0.5 * (edges[1:] + edges[:-1])
    sol = res.potential
    yc = g.notch_centre[1]
    axis = np.vstack([xc, np.full_like(xc, yc), np.full_like(xc, 0.5 * g.thickness)])
    return {
        "R_eq": float(res.resistance[0]), "R_eq_end": float(res.resistance[-1]),
        "T_notch_centre": float(res.probe_temperatures[-1, 0]),
        "T_notch_mean": res.subdomain_average("notch"),
        "T_max": float(np.max(res.T)),
        "x_bins": xc, "V_profile": slab_average(sol.basis, sol.u, 0, edges),
        "T_profile": res.slab_average(0, edges), "V_centreline": sol.probe(axis.T),
        "times": res.times, "T_notch_history": res.probe_temperatures[:, 0],
        "joule_energy": res.joule_energy, "energy_balance_error": res.energy_balance_error,
        "ndofs": int(res.basis.N), "h": h, "nsteps": nsteps,
    }


# --------------------------------------------------------------------------- slab
def slab_conduction(length: float = 10e-3, h: float = 0.5e-3, t_end: float = 5.0,
                    nsteps: int | None = None, T0: float = T_ROOM, T1: float = T_ROOM + 100.0,
                    theta: float = 1.0, material: Material = STEEL_304L, npoints: int = 21) -> dict:
    """1D slab (paper 003): insulated at x = 0, T1 at x = L from t = 0, initially T0.

    Meshed as a bar of one h x h cell section. Default nsteps keeps dt ~ h^2 / alpha.

    Returns
    -------
    dict
        ``x`` [m], ``T`` (FEM at t_end) and ``T_exact`` [K], ``max_error`` [K],
        ``relative_error`` (max error / ``|T1 - T0|``), ``h``, ``dt``.
    """
    if nsteps is None:
        nsteps = max(10, int(math.ceil(t_end * material.diffusivity / (0.5 * h * h))))
    mesh = box_mesh(length, h, h, n=(int(round(length / h)), 1, 1))
    x = np.linspace(0.0, length, npoints)
    pts = np.vstack([x, np.full_like(x, 0.5 * h), np.full_like(x, 0.5 * h)])
    res = transient_conduction(mesh, material.conductivity, material.rho_c, T0, t_end,
                               t_end / nsteps, fixed_T={"x1": T1}, theta=theta, probes=pts.T,
                               record_every=nsteps)
    t_fem = res.probe_temperatures[-1]
    t_ex = slab_temperature(x, t_end, length, material.diffusivity, T0, T1)
    err = float(np.max(np.abs(t_fem - t_ex)))
    return {"x": x, "T": t_fem, "T_exact": t_ex, "max_error": err,
            "relative_error": err / abs(T1 - T0), "h": h, "dt": t_end / nsteps}


# --------------------------------------------------------------------------- references
def rod_reference(radius: float = 1e-3, length: float = 5e-3, hs=(0.2e-3, 0.1e-3, 0.05e-3),
                  material: Material = STEEL_304L) -> dict:
    """Mesh-converged rod resistance: {'R_eq': Convergence}."""
    return converged(lambda h: {"R_eq": rod_resistance(radius, length, h, material)["R_eq"]},
                     hs)


def plate_reference(geometry: PlateGeometry = PlateGeometry(), hs=(2e-3, 1e-3, 0.5e-3),
                    voltage: float = 1.0, order: int = 2,
                    material: Material = STEEL_304L) -> dict:
    """Mesh-converged plate potentials at the control points and R_eq."""
    def run(h):
        out = plate_potential(geometry, h, voltage, order=order, material=material)
        out.pop("ndofs")
        return out
    return converged(run, hs)


def notched_bar_reference(geometry: NotchedBarGeometry = NotchedBarGeometry(),
                          hs=(0.2e-3, 0.1e-3, 0.05e-3), **kwargs) -> dict:
    """Mesh-converged R_eq, notch temperatures and T_max of :func:`notched_bar`
    (time step refined with h)."""
    keys = ("R_eq", "T_notch_centre", "T_notch_mean", "T_max")

    def run(h):
        out = notched_bar(geometry, h, **kwargs)
        return {k: out[k] for k in keys}
    return converged(run, hs)


# --------------------------------------------------------------------------- cracked bar
def cracked_bar(geometry=None, h: float = 0.25e-3, material: Material = STEEL_304L, order: int = 1,
                front_refinement: float = 0.25) -> dict:
    """Resistance of the square bar between its end faces with and without its edge crack
    (:class:`~yade_electro.fem.meshes.CrackedBarGeometry`).

    Returns
    -------
    dict
        ``R_crack``, ``R_intact`` (= rho L / W^2, exact: a bar), ``increment`` =
        R_crack / R_intact - 1, ``ndofs``, ``h``.
    """
    from .meshes import CrackedBarGeometry, cracked_bar_mesh
    g = CrackedBarGeometry() if geometry is None else geometry
    sol = solve_potential(cracked_bar_mesh(g, h, front_refinement), material.resistivity, {"end1": 1.0, "end0": 0.0},
                          order=order)
    r = sol.equivalent_resistance("end1", "end0")
    r0 = bar_resistance(material.resistivity, g.length, g.width ** 2)
    return {"R_crack": r, "R_intact": r0, "increment": r / r0 - 1.0, "ndofs": sol.ndofs, "h": h}


def cracked_bar_reference(geometry=None, hs=(0.35e-3, 0.25e-3, 0.18e-3), order: int = 2,
                          material: Material = STEEL_304L, progress=None) -> dict:
    """Mesh-converged crack increment of :class:`~yade_electro.fem.meshes.CrackedBarGeometry`:
    ``convergence`` (a :class:`Convergence` of the increment over ``hs``, P``order`` elements,
    expected order 1: the potential near the front goes as r^(1/2)), ``closed_form``
    (:func:`edge_crack_increment`) and the runs (``runs``: one dict per h).
    ``progress(msg)`` is called before each mesh."""
    from .convergence import richardson
    from .meshes import CrackedBarGeometry
    g = CrackedBarGeometry() if geometry is None else geometry
    runs = []
    for k, h in enumerate(hs):
        if progress is not None:
            progress(f"FEM P{order} h = {h * 1e3:.3g} mm ({k + 1}/{len(hs)})")
        runs.append(cracked_bar(g, h, material, order))
    conv = richardson([r["h"] for r in runs], [r["increment"] for r in runs], expected_order=1.0)
    return {"convergence": conv, "closed_form": edge_crack_increment(g.width, g.length, g.crack_depth),
            "runs": runs}
