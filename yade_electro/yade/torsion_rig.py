"""A torsion test rig in YADE: one end layer of a bonded bar clamped, the other turned about
the bar's axis at a prescribed rate, the reaction torques read by YADE's C++.

The grips are the elements whose centre lies within ``grip_depth`` of an end face. Their six
degrees of freedom are blocked (``blockedDOFs = 'xyzXYZ'``): the bottom grip stays put, the
top grip is turned by a ``RotationEngine`` about the axis (``rotateAroundZero``: positions
rotate exactly, not along the tangent). The twist angle follows ``theta(t)``: angular velocity
``rate * min(1, t / ramp_time)`` (a linear start, so the loading sends no step wave), the
angle the integral of it, accumulated step by step as the rotation engine applies it.

Reading, when asked (``TorsionRig.record``, e.g. from a ``TorsionRig.recorder``): the angle
[rad], the torques [N m] that the bar exerts on each grip about the axis
(``utils.sumTorques`` over the grip's ids: C++, ~0.1 ms), the kinetic energy of the scene and
the elastic energy of the bonds (``Law2_ScGeom6D_CohFrictPhys_CohesionMoment.elasticEnergy``,
when that law runs) [J].

Units: SI (m, s, rad, N m, J).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from .runtime import import_yade

__all__ = ["TorsionRig", "grip_layers"]


def grip_layers(axial, length: float, depth: float):
    """(bottom, top) boolean masks of the elements whose axial coordinate [m] is within
    ``depth`` [m] of the end faces 0 and ``length``."""
    axial = np.asarray(axial, float)
    if not depth > 0:
        raise ValueError(f"grip depth must be > 0 m, got {depth}")
    bottom, top = axial <= depth, axial >= length - depth
    if not bottom.any() or not top.any():
        raise ValueError(f"a grip of depth {depth:g} m holds no element (bottom {int(bottom.sum())}, top "
                         f"{int(top.sum())}); make grip_depth larger")
    if np.any(bottom & top):
        raise ValueError(f"grip depth {depth:g} m makes the grips overlap in a bar of length {length:g} m")
    return bottom, top


class TorsionRig:
    """Clamp one end of a bar in YADE and twist the other.

    Parameters
    ----------
    ids : sequence of int
        Body ids of the bar's elements.
    axial : (n,) array
        Each element's coordinate along the axis [m] (0 at the clamped face).
    origin, axis : 3-vectors
        A point of the axis [m] (the clamped face's centre) and its direction.
    length : float
        Bar length [m].
    grip_depth : float
        Elements whose centre is within this distance [m] of an end face form the grips.
    rate : float
        Twist rate [rad/s] once started.
    ramp_time : float
        Duration [s] of the linear start of the rate (0: full rate at once).
    label : str
        Label of the rig's PyRunner (and prefix of its RotationEngine's).

    Put ``rig.engines`` in ``O.engines`` before ``NewtonIntegrator`` (the rotation engine) and
    ``rig.runner`` after it; call ``rig.record()`` whenever a record is wanted (e.g. from a
    PyRunner every N steps).
    """

    def __init__(self, ids, axial, origin, axis, length: float, grip_depth: float, rate: float,
                 ramp_time: float = 0.0, label: str = "torsion", O=None):
        yade = import_yade()
        from yade import wrapper as W
        self.O = O if O is not None else yade.Omega()
        if not (isinstance(label, str) and label.isidentifier()) or label in _RIGS:
            raise ValueError(f"rig label must be a new Python identifier, got {label!r} (taken: {sorted(_RIGS)})")
        if not rate > 0:
            raise ValueError(f"twist rate must be > 0 rad/s, got {rate}")
        if not ramp_time >= 0:
            raise ValueError(f"ramp_time must be >= 0 s, got {ramp_time}")
        ids = np.asarray(ids, dtype=np.int64)
        axial = np.asarray(axial, float)
        if ids.shape != axial.shape:
            raise ValueError(f"ids and axial must have one shape, got {ids.shape} and {axial.shape}")
        bottom, top = grip_layers(axial, length, grip_depth)
        self.bottom_ids = ids[bottom].tolist()
        self.top_ids = ids[top].tolist()
        self.origin = np.asarray(origin, float).reshape(3)
        a = np.asarray(axis, float).reshape(3)
        self.axis = a / np.linalg.norm(a)
        self.length = float(length)
        self.grip_depth = float(grip_depth)
        self.rate, self.ramp_time = float(rate), float(ramp_time)
        self.theta = 0.0
        self._callbacks, self._runners = [], []
        for i in self.bottom_ids + self.top_ids:
            b = self.O.bodies[i]
            b.state.blockedDOFs = "xyzXYZ"
            b.state.vel = (0, 0, 0)
            b.state.angVel = (0, 0, 0)
        self.label = label
        self.rotation = W.RotationEngine(ids=self.top_ids, rotationAxis=tuple(self.axis), rotateAroundZero=True,
                                         zeroPoint=tuple(self.origin), angularVelocity=0.0,
                                         label=self.label + "_rotation")
        self.runner = W.PyRunner(iterPeriod=1, command=f"import yade_electro.yade.torsion_rig as _t; "
                                                       f"_t._RIGS[{self.label!r}].advance()",
                                 label=self.label)
        _RIGS[self.label] = self
        self._laws = [f for e in self.O.engines for f in (getattr(getattr(e, "lawDispatcher", None),
                                                                      "functors", None) or [])
                      if hasattr(f, "elasticEnergy")]
        from yade import utils
        self._utils = utils
        # mean axial position of each grip (the twisted length is between them)
        self.grip_axial = (float(axial[bottom].mean()), float(axial[top].mean()))

    @property
    def engines(self) -> list:
        """The engines to place before NewtonIntegrator."""
        return [self.rotation]

    @property
    def free_length(self) -> float:
        """Distance [m] between the grips' mean axial positions: the twisted length."""
        return self.grip_axial[1] - self.grip_axial[0]

    def hold(self):
        """Stop turning: the top grip stays where it is from the next step on."""
        self.rate, self.ramp_time = 0.0, 0.0
        self.rotation.angularVelocity = 0.0

    def angular_velocity(self, t: float) -> float:
        """The prescribed twist rate [rad/s] at time t [s]."""
        if self.ramp_time > 0 and t < self.ramp_time:
            return self.rate * t / self.ramp_time
        return self.rate

    def advance(self):
        """Per step, after NewtonIntegrator: account for the rotation just applied and set the
        rate of the next step."""
        O = self.O
        self.theta += self.rotation.angularVelocity * O.dt
        self.rotation.angularVelocity = self.angular_velocity(O.time)

    def torques(self):
        """(top, bottom) torques [N m] the bar exerts on the grips about the axis, this step."""
        u = self._utils
        ax, pt = tuple(self.axis), tuple(self.origin)
        return u.sumTorques(self.top_ids, ax, pt), u.sumTorques(self.bottom_ids, ax, pt)

    def record(self) -> dict:
        """One record (angle, torques, energies) of this step, as a dict."""
        O = self.O
        t_top, t_bot = self.torques()
        kin = float(self._utils.kineticEnergy())
        el = float(sum(f.elasticEnergy() for f in self._laws)) if self._laws else float("nan")
        return dict(iter=int(O.iter), time=float(O.time), theta=float(self.theta), torque_top=float(t_top),
                    torque_bottom=float(t_bot), kinetic=kin, elastic=el)

    def recorder(self, callback, iterPeriod: int):
        """A PyRunner that calls ``callback()`` every ``iterPeriod`` steps (put it after the
        engines whose results it reads); removed with the rig."""
        from yade import wrapper as W
        if isinstance(iterPeriod, bool) or int(iterPeriod) != iterPeriod or iterPeriod < 1:
            raise ValueError(f"iterPeriod must be an integer >= 1, got {iterPeriod!r}")
        k = len(self._callbacks)
        self._callbacks.append(callback)
        runner = W.PyRunner(iterPeriod=int(iterPeriod), label=f"{self.label}_recorder{k}",
                            command=f"import yade_electro.yade.torsion_rig as _t; _t._RIGS[{self.label!r}]._callbacks[{k}]()")
        self._runners.append(runner)
        return runner

    def remove(self):
        """Take the rig's engines (and recorders) out of O.engines and forget it."""
        mine = [self.runner, self.rotation] + self._runners
        self.O.engines = [e for e in self.O.engines if not any(e is m for m in mine)]
        _RIGS.pop(self.label, None)


#: live rigs by label (the PyRunner's command finds its rig here)
_RIGS = {}


def get_rig(label: str) -> Optional[TorsionRig]:
    return _RIGS.get(label)
