"""Material data as small frozen objects, validated once, and the rules that turn per-element
values into per-edge values.

:class:`Material` carries the electrical resistivity at a reference temperature and its
temperature coefficient (``rho_e(T) = rho_0 (1 + beta (T - T_0))``), and the thermal data
(density, specific heat, conductivity). Each value is a scalar or one value per element.

An edge between two elements is two half-length rods in series, so

* its resistivity is the mean of its two elements' resistivities (:func:`edge_resistivity`),
* its conductivity is the harmonic mean of theirs (:func:`edge_conductivity`),

and the conductances are ``c = g / rho_edge`` [S] and ``G = lambda_edge g`` [W/K] for the
geometric factor ``g`` [m] of a conductance law (:mod:`yade_electro.laws.factors`).

Units: SI (ohm m, 1/K, K, kg/m^3, J/(kg K), W/(m K)).
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Optional

import numpy as np

from .errors import MaterialError

__all__ = ["Material", "positive_property", "real_number", "edge_resistivity", "edge_conductivity", "in_series",
           "electrical_conductance", "thermal_conductance_of"]


def real_number(name: str, value, *, what: str = "a real number") -> float:
    """``value`` as a finite float, or MaterialError naming ``name`` (strings, None, complex,
    booleans, NaN and inf are refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise MaterialError(f"{name} must be {what}, got {value!r} ({type(value).__name__})")
    v = float(value)
    if not np.isfinite(v):
        raise MaterialError(f"{name} must be finite, got {value!r}")
    return v


def positive_property(name: str, value, n: Optional[int] = None, unit: str = "") -> np.ndarray:
    """``value`` as a float scalar or (n,) array, or MaterialError if it is not made of finite
    numbers > 0. ``unit`` (e.g. ``" (kg/m^3)"``) goes into the message."""
    if isinstance(value, (str, bytes)) or value is None or isinstance(value, (bool, np.bool_)):
        raise MaterialError(f"{name} must be a positive number{unit} or one per element, got {value!r}")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise MaterialError(f"{name} must be a positive number{unit} or one per element, got {value!r}") from None
    if a.ndim not in (0, 1) or (a.ndim == 1 and n is not None and a.shape[0] != n):
        raise MaterialError(f"{name} must be a scalar or one value per element ({n}), got shape {a.shape}")
    ok = np.isfinite(a) & (a > 0)
    if not np.all(ok):
        bad = a if a.ndim == 0 else a[~ok][:5]
        raise MaterialError(f"{name} must be finite and > 0{unit}; got {np.atleast_1d(bad).tolist()}")
    return a


def edge_resistivity(rho, edges) -> np.ndarray:
    """Resistivity of each edge [ohm m]: the scalar, or the mean of its two elements' values
    (two half rods in series)."""
    rho = np.asarray(rho, dtype=float)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if rho.ndim == 0:
        return np.full(edges.shape[0], float(rho))
    return 0.5 * (rho[edges[:, 0]] + rho[edges[:, 1]])


def edge_conductivity(lam, edges) -> np.ndarray:
    """Conductivity of each edge [W/(m K)]: the scalar, or the harmonic mean of its two
    elements' values (two half rods in series)."""
    lam = np.asarray(lam, dtype=float)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if lam.ndim == 0:
        return np.full(edges.shape[0], float(lam))
    a, b = lam[edges[:, 0]], lam[edges[:, 1]]
    return 2.0 * a * b / (a + b)


def electrical_conductance(factor, resistivity, edges, series=None) -> np.ndarray:
    """Electrical conductance of each edge [S]: its geometric factor ``factor`` [m] over the
    edge's resistivity [ohm m] (:func:`edge_resistivity`), with ``series`` [ohm] per edge (a
    contact film) in series when given. The one place where a factor meets a resistivity."""
    return in_series(np.asarray(factor, dtype=float) / edge_resistivity(resistivity, edges), series)


def in_series(conductance, series=None) -> np.ndarray:
    """Conductances [S] with resistances ``series`` [ohm] (per edge, or a scalar) in series:
    ``1 / (1/c + R)`` where c > 0, 0 elsewhere; unchanged when ``series`` is None or 0."""
    c = np.asarray(conductance, dtype=float)
    if series is None or np.ndim(series) == 0 and not series:
        return c
    with np.errstate(divide="ignore"):
        return np.where(c > 0, 1.0 / (1.0 / np.where(c > 0, c, 1.0) + np.asarray(series, float)), 0.0)


def thermal_conductance_of(factor, conductivity, edges) -> np.ndarray:
    """Thermal conductance of each edge [W/K]: the edge's conductivity [W/(m K)]
    (:func:`edge_conductivity`) times its geometric factor ``factor`` [m]. The one place where
    a factor meets a conductivity."""
    return edge_conductivity(conductivity, edges) * np.asarray(factor, dtype=float)


@dataclass(frozen=True, eq=False)
class Material:
    """Electrical and thermal data of the solid (SI units).

    Parameters
    ----------
    resistivity : float or (n,), optional
        Electrical resistivity rho_0 [ohm m] at ``reference_temperature``, > 0 (304L: 0.73e-6).
        None for a heat-only model.
    beta : float
        Temperature coefficient of the resistivity [1/K] (0: constant).
    reference_temperature : float, optional
        T_0 [K] of rho_e(T); needed when ``beta != 0``.
    density : float or (n,), optional [kg/m^3]
    specific_heat : float or (n,), optional [J/(kg K)]
    conductivity : float or (n,), optional thermal conductivity lambda [W/(m K)]

    Raises
    ------
    MaterialError
        A value that is not a finite positive number (or array of them), a string, NaN.
    """

    resistivity: object = None
    beta: float = 0.0
    reference_temperature: Optional[float] = None
    density: object = None
    specific_heat: object = None
    conductivity: object = None

    def __post_init__(self):
        if self.resistivity is not None:
            object.__setattr__(self, "resistivity", positive_property("resistivity", self.resistivity,
                                                                       unit=" (ohm m)"))
        object.__setattr__(self, "beta", real_number("beta (temperature coefficient of the resistivity, 1/K)",
                                                     self.beta))
        if self.reference_temperature is not None:
            object.__setattr__(self, "reference_temperature",
                               real_number("reference_temperature (K)", self.reference_temperature))
        elif self.beta != 0.0:
            raise MaterialError("beta != 0 needs reference_temperature= (K), the T_0 of rho_e(T) = "
                                "rho_0 (1 + beta (T - T_0))")
        for name, unit in (("density", " (kg/m^3)"), ("specific_heat", " (J/(kg K))"),
                           ("conductivity", " (W/(m K))")):
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, positive_property(name, v, unit=unit))

    @property
    def thermal(self) -> bool:
        """True when density, specific heat and conductivity are all given."""
        return all(v is not None for v in (self.density, self.specific_heat, self.conductivity))

    def require_thermal(self):
        """Raise MaterialError unless the thermal data are complete."""
        missing = [k for k in ("density", "specific_heat", "conductivity") if getattr(self, k) is None]
        if missing:
            raise MaterialError(f"the thermal model needs {', '.join(missing)} (SI units)")

    def require_electrical(self):
        """Raise MaterialError unless a resistivity is given."""
        if self.resistivity is None:
            raise MaterialError("the electrical model needs resistivity= (ohm m)")

    def check_size(self, n: int):
        """Raise MaterialError if a per-element array does not have ``n`` values."""
        for name in ("resistivity", "density", "specific_heat", "conductivity"):
            v = getattr(self, name)
            if v is not None and np.ndim(v) == 1 and np.shape(v)[0] != n:
                raise MaterialError(f"{name} has {np.shape(v)[0]} values but the packing has {n} elements")

    def resistivity_at(self, temperature=None) -> np.ndarray:
        """rho_e(T) [ohm m] per element (scalar when constant); MaterialError where it is <= 0."""
        self.require_electrical()
        if self.beta == 0.0 or temperature is None:
            return self.resistivity
        T = np.asarray(temperature, dtype=float)
        rho = self.resistivity * (1.0 + self.beta * (T - self.reference_temperature))
        if not np.all(rho > 0):
            bad = np.flatnonzero(~(np.atleast_1d(rho) > 0))
            raise MaterialError(
                f"rho_e(T) = rho_0 (1 + beta (T - T_0)) is <= 0 at {bad.size} element(s) (e.g. element {bad[0]}, "
                f"T = {np.atleast_1d(T)[bad[0]]:.6g}); beta={self.beta:g} does not fit this temperature range")
        return rho

    def heat_capacity_density(self) -> np.ndarray:
        """rho c [J/(m^3 K)] (scalar or per element)."""
        self.require_thermal()
        return self.density * self.specific_heat

    def diffusivity(self) -> np.ndarray:
        """lambda / (rho c) [m^2/s]."""
        return self.conductivity / self.heat_capacity_density()
