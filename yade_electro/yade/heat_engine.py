"""The heat-only engine (no electrodes)."""

from __future__ import annotations

import logging


from . import registry

from .electrothermal_engine import ElectroThermalEngine
__all__ = ["HeatEngine"]

log = logging.getLogger(__name__)


@registry.engine_type
class HeatEngine(ElectroThermalEngine):
    """Heat conduction only (no electrodes): :class:`ElectroThermalEngine` with
    ``electrodes=None``, the same boundary conditions (``fixed``, ``flux``, ``convection``,
    ``sources``; nodes or surfaces), time steps or ``steady=True``. Its default label is
    'heat'. (Not YADE's own ``ThermalEngine``, which needs a FlowEngine.)"""

    DEFAULT_LABEL = "heat"

    def __init__(self, density=None, specific_heat=None, conductivity=None, temperature=None, **kwargs):
        if kwargs.get("electrodes") is not None:
            raise ValueError("HeatEngine conducts heat only: use ElectroThermalEngine for electrodes")
        kwargs["electrodes"] = None
        super().__init__(density=density, specific_heat=specific_heat, conductivity=conductivity,
                         temperature=temperature, **kwargs)
