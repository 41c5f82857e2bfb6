"""Exceptions of yade-electro: each names what was found and what to do about it."""

__all__ = ["ElectroError", "GraphError", "BoundaryConditionError", "MaterialError",
           "SolverError", "ThermalError"]


class ElectroError(Exception):
    """Base class of every error raised by yade-electro."""


class GraphError(ElectroError, ValueError):
    """The contact graph is malformed (no spheres, bad radius, bad edges, unknown ids)."""


class BoundaryConditionError(ElectroError, ValueError):
    """Electrodes or imposed currents are inconsistent (empty, overlapping, unknown)."""


class MaterialError(ElectroError, ValueError):
    """A material property is out of range (zero or negative resistivity, conductivity...)."""


class SolverError(ElectroError, RuntimeError):
    """A linear solve failed to reach its tolerance or produced non-finite values."""


class ThermalError(ElectroError, RuntimeError):
    """The thermal integration cannot go on (non-finite temperatures, unstable step)."""
