"""YADE adapter of yade-electro: contact graphs read from ``O``, the electrical engine as a
``PyRunner``, write-back of results to bodies, and packing recipes.

Importing this subpackage does not import YADE by itself; the functions that need it do.
"""

from .runtime import import_yade, in_yade  # noqa: E402
from .scene import SceneReader, write_body_attribute, predicate_selector  # noqa: E402
from .engines import ElectricalEngine, ElectroThermalEngine, ensure_thermal_state, get_engine, ENGINES  # noqa: E402

__all__ = ["import_yade", "in_yade", "SceneReader", "write_body_attribute", "predicate_selector",
           "ElectricalEngine", "ElectroThermalEngine", "ensure_thermal_state", "get_engine", "ENGINES"]
