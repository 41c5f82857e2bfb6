"""YADE adapter of yade-electro: the engines for ``O.engines``, their option objects, contact
graphs read from ``O``, write-back of results to bodies, save/load, bonding, and the launcher
without open ports.

One import gives what a YADE script needs::

    from yade_electro.yade import ElectricalEngine, Material, Electrode

Importing this subpackage does not import YADE by itself; the functions that need it do.
"""

from ..core.materials import Material
from ..laws.law import Law
from ..network.heat_conditions import Convection, FixedTemperature, HeatFlux, HeatSource
from ..physics.expansion import AlphaTable
from ..physics.integrator import Integrator
from .electrical_engine import ElectricalEngine
from .electrothermal_engine import ElectroThermalEngine
from .expansion_engine import ThermalExpansion
from .heat_engine import HeatEngine
from .options import (Electrode, InitialTemperature, Materials, Output, Reader, Wall, electrodes_from_dict,
                      walls_from_dict)
from .registry import ENGINES, attach, get_engine
from .runtime import import_yade, in_yade
from .scene import SceneReader, predicate_selector
from .writeback import ensure_thermal_state, write_body_attribute

__all__ = [
    # the engines
    "ElectricalEngine", "ElectroThermalEngine", "HeatEngine", "ThermalExpansion",
    # their options
    "Material", "Materials", "Electrode", "Wall", "FixedTemperature", "HeatFlux", "Convection", "HeatSource",
    "InitialTemperature", "AlphaTable", "Law", "Integrator", "Reader", "Output", "electrodes_from_dict", "walls_from_dict",
    # engines in a scene
    "attach", "get_engine", "ENGINES",
    # scene access
    "import_yade", "in_yade", "SceneReader", "write_body_attribute", "predicate_selector", "ensure_thermal_state",
]
