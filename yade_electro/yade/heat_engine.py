"""The heat-only engine (no electrodes)."""

from __future__ import annotations

from typing import Optional

from ..core.errors import BoundaryConditionError
from ..physics.integrator import Integrator
from . import registry
from .electrothermal_engine import ElectroThermalEngine
from .engine_base import keyword_only
from .options import Output, Reader, thermal_settings

__all__ = ["HeatEngine"]


@registry.engine_type
class HeatEngine(ElectroThermalEngine):
    """Heat conduction only: :class:`ElectroThermalEngine` without electrodes (its default
    label is ``'heat'``). The same thermal boundaries (``FixedTemperature``, ``HeatFlux``,
    ``Convection``, ``HeatSource``, on elements or surfaces; ``Wall`` in a granular bed), time
    steps or ``Integrator(steady=True)``. Not YADE's own ``ThermalEngine``, which needs a
    FlowEngine.

    Parameters
    ----------
    material, boundaries, temperature, law, integrator, reader, output, iterPeriod, label
        As for :class:`ElectroThermalEngine` (``material`` needs no resistivity).

    Raises
    ------
    BoundaryConditionError
        An ``Electrode`` among the boundaries (use :class:`ElectroThermalEngine`).
    ValueError
        ``Output(write_back=...)``: a heat engine writes no potential.
    """

    DEFAULT_LABEL = "heat"

    @keyword_only
    def __init__(self, *, material, boundaries=(), temperature, law="auto", integrator: Integrator = Integrator(),
                 reader: Reader = Reader(), output: Output = Output(), iterPeriod: int = 1,
                 label: Optional[str] = None):
        if output.write_back not in (None, Output.write_back):
            raise ValueError(f"HeatEngine writes no potential, so Output(write_back={output.write_back!r}) has nothing "
                             "to write (the temperatures go to b.state.temp): leave write_back out")
        settings = thermal_settings(material, boundaries, temperature, law, integrator, reader, output, "HeatEngine")
        if settings["electrodes"] is not None:
            raise BoundaryConditionError("HeatEngine conducts heat only: use ElectroThermalEngine for electrodes")
        self._setup(**settings, iterPeriod=iterPeriod, label=label)
