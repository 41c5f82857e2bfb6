"""YADE adapter of yade-electro: contact graphs read from ``O``, the engines as ``PyRunner``s,
write-back of results to bodies, save/load, bonding, and the launcher without open ports.

Importing this subpackage does not import YADE by itself; the functions that need it do.
"""

from .runtime import import_yade, in_yade  # noqa: E402
from .scene import SceneReader, ensure_thermal_state, write_body_attribute, predicate_selector  # noqa: E402
from .registry import ENGINES, attach, get_engine  # noqa: E402
from .electrical_engine import ElectricalEngine  # noqa: E402
from .electrothermal_engine import ElectroThermalEngine  # noqa: E402
from .heat_engine import HeatEngine  # noqa: E402

__all__ = ["import_yade", "in_yade", "SceneReader", "write_body_attribute", "predicate_selector",
           "ElectricalEngine", "ElectroThermalEngine", "HeatEngine", "ensure_thermal_state", "get_engine", "ENGINES", "attach"]
