"""Resolved grains that move (issue 35, numpy only): each grain a rigid bonded sub-packing of
its shape with its own temperature field, grains joined where they touch through a contact
resistance.

A :class:`GrainTemplate` is made once per grain form
(:func:`yade_electro.packing.grains.grain_template`: ``dense_packing`` of its
:class:`~yade_electro.geometry.shapes.Shape`, the 'voronoi' law's network, factors and cell
volumes): a rigid motion changes none of them, so a grain at any pose reuses its template's.
Where two grains are (their members' spheres overlap: the DEM presses them together), the
contact is taken as flat: the plane normal to the two solids' surfaces there (their signed
distances' gradients, each shape evaluated in its grain's frame) through the middle of their
overlap, and its patch is the part of that plane inside both solids, or, when the spheres touch
while the surfaces are still apart (the spheres' tops under the faces), within half the
surfaces' largest distance at the spheres' contacts of both: the surfaces touch where they are
at least as close as where the DEM's spheres do. The grains' elements are joined across it
by :func:`~yade_electro.network.grain_contact.plane_contact_links`. :func:`grain_network`
assembles the network of a set of grains at their poses (edges, conductances, capacities) for
:class:`~yade_electro.network.transient.HeatSolver`.

Units: m, m^3, W/(m K), m^2 K/W, W/K, J/K.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence, Union

import numpy as np

from ..core.errors import BoundaryConditionError
from ..geometry.rigid import rigid_pose
from .grain_contact import contact_resistance_value, plane_contact_geometry

__all__ = ["GrainTemplate", "rigid_pose", "grain_contact_geometry", "grain_contact", "grain_network"]


@dataclass(frozen=True, eq=False)
class GrainTemplate:
    """A grain form in its own frame: ``shape`` and its packing's ``centres`` (n, 3) [m],
    ``radii`` (n,) [m], the 'voronoi' network ``edges`` (k, 2), factors ``factor`` (k,) [m]
    and cell ``volume`` (n,) [m^3]."""

    shape: object
    centres: np.ndarray
    radii: np.ndarray
    edges: np.ndarray
    factor: np.ndarray
    volume: np.ndarray

    @property
    def n(self) -> int:
        return int(self.centres.shape[0])

    def placed(self, rotation, translation) -> np.ndarray:
        """The centres [m] at the pose ``x = R x_ref + t``."""
        return self.centres @ np.asarray(rotation, float).T + np.asarray(translation, float)


def _inside(template: GrainTemplate, R, t, within: float = 0.0):
    """``f(points) -> mask``: the points inside the posed grain's solid, or within ``within`` [m] of it."""
    def f(x):
        return np.asarray(template.shape.sdf((np.asarray(x, float) - t) @ R), float) <= within
    return f


_NO_CONTACT = (np.zeros((0, 2), np.int64), np.zeros(0), np.zeros(0), np.zeros(0), 0.0)


def grain_contact_geometry(a: GrainTemplate, pose_a, b: GrainTemplate, pose_b, samples: int = 40_000):
    """The contact of grains a and b at their poses ``(R, t)`` as geometry: (pairs (k, 2) of
    element indices (of a, of b), their shared face areas ``A_ij`` [m^2], the elements'
    distances to the contact plane ``d_i``, ``d_j`` [m], the patch area [m^2]); empty when no
    member spheres of the two overlap. Worked in a's frame (b at its pose relative to a), so
    that it depends on the relative pose only: a rigid motion of the pair changes nothing."""
    (Ra, ta), (Rb, tb) = pose_a, pose_b
    Ra, Rb = np.asarray(Ra, float), np.asarray(Rb, float)
    Rb, tb = Ra.T @ Rb, (np.asarray(tb, float) - np.asarray(ta, float)) @ Ra     # b in a's frame
    Ra, ta = np.eye(3), np.zeros(3)
    ca, cb = a.centres, b.placed(Rb, tb)
    from scipy.spatial import cKDTree
    lists = cKDTree(cb).query_ball_point(ca, float(a.radii.max() + b.radii.max()))
    ia = np.repeat(np.arange(len(lists)), [len(x) for x in lists])
    ib = np.fromiter((j for x in lists for j in x), dtype=np.int64, count=ia.size)
    d = np.linalg.norm(cb[ib] - ca[ia], axis=1) if ia.size else np.zeros(0)
    over = d < a.radii[ia] + b.radii[ib]
    if not np.any(over):
        return _NO_CONTACT
    ia, ib, d = ia[over], ib[over], d[over]
    u = (cb[ib] - ca[ia]) / d[:, None]
    # the lens of each pair lies where its two spheres' surfaces cross: its centre on the line
    x = (a.radii[ia] ** 2 - b.radii[ib] ** 2 + d ** 2) / (2.0 * d)
    origin = (ca[ia] + x[:, None] * u).mean(axis=0)
    # the plane: normal to the solids' surfaces there (a's outward normal, b's inward), through
    # the middle of their overlap (where both signed distances are equal)
    for _ in range(3):
        ga = a.shape.gradient(origin[None])[0]
        gb = Rb @ b.shape.gradient(((origin - tb) @ Rb)[None])[0]
        normal = ga - gb
        normal = normal / np.linalg.norm(normal) if np.linalg.norm(normal) > 0 else u.mean(axis=0)
        sa = float(a.shape.sdf(origin[None])[0])
        sb = float(b.shape.sdf(((origin - tb) @ Rb)[None])[0])
        origin = origin + 0.5 * (sb - sa) * normal
    axis = np.eye(3)[int(np.argmin(np.abs(normal)))]
    u_axis = np.cross(normal, axis)
    v_axis = np.cross(normal, u_axis)
    # where the DEM's spheres touch, the two surfaces may still be apart (the spheres' tops lie
    # under the faces): the surfaces are in contact where they are at least as close as at the
    # farthest apart of the spheres' contacts (their lenses' centres); overlapping solids: where
    # the plane is inside both
    lens = ca[ia] + x[:, None] * u
    apart = float(np.max(a.shape.sdf(lens) + b.shape.sdf((lens - tb) @ Rb)))
    within = 0.5 * max(apart, 0.0) + 1e-9 * float(a.radii.mean() + b.radii.mean())
    ina, inb = _inside(a, Ra, ta, within), _inside(b, Rb, tb, within)
    # the patch: the plane's points inside both solids; found on a coarse grid over the grains'
    # reach, then sampled finely over its bounding rectangle
    half = float(max(np.max(np.linalg.norm(ca - origin, axis=1)), np.max(np.linalg.norm(cb - origin, axis=1))))
    k = 200
    s = (np.arange(k) + 0.5) / k * 2 * half - half
    U, V = np.meshgrid(s, s, indexing="ij")
    grid = origin + U.reshape(-1, 1) * u_axis + V.reshape(-1, 1) * v_axis
    hit = ina(grid) & inb(grid)
    if not np.any(hit):
        return _NO_CONTACT
    step = 2 * half / k
    ext_u = (float(U.ravel()[hit].min()) - step, float(U.ravel()[hit].max()) + step)
    ext_v = (float(V.ravel()[hit].min()) - step, float(V.ravel()[hit].max()) + step)
    pairs, A, da, db, area = plane_contact_geometry(ca, cb, origin, normal, u_axis, ext_u, ext_v, samples=samples,
                                                    inside=lambda p: ina(p) & inb(p))
    if area <= 0.0:
        return _NO_CONTACT
    return pairs, A, da, db, area


def grain_contact(a: GrainTemplate, pose_a, b: GrainTemplate, pose_b, resistance, conductivity,
                  samples: int = 40_000):
    """The links between grains a and b at their poses ``(R, t)``: (pairs (k, 2) of element
    indices (of a, of b), conductances ``A_ij / (d_i / k + R_c + d_j / k)`` [W/K], the patch
    area [m^2]); empty when no member spheres of the two overlap
    (:func:`grain_contact_geometry`). ``resistance``: R_c [m^2 K/W], or ``f(pressure) -> R_c``
    given the mean pressure 0 (a caller with forces passes a number)."""
    pairs, A, da, db, area = grain_contact_geometry(a, pose_a, b, pose_b, samples)
    if not pairs.size:
        return pairs, A, area
    Rc = contact_resistance_value(resistance(0.0) if callable(resistance) else resistance)
    lam = float(conductivity)
    return pairs, A / ((da + db) / lam + Rc), area


def grain_network(grains: Sequence, poses: Sequence, conductivity: float, rho_c: float,
                  resistance: Union[float, Callable], samples: int = 40_000):
    """The heat network of ``grains`` (GrainTemplate each) at ``poses`` ((R, t) each): (edges
    (m, 2), conductances [W/K], capacities [J/K], the first node of each grain, the contacts
    as {(i, j): area [m^2]}). Nodes: grain 0's elements, then grain 1's, ..."""
    if len(grains) != len(poses):
        raise BoundaryConditionError(f"{len(grains)} grains but {len(poses)} poses")
    lam = float(conductivity)
    first = np.cumsum([0] + [g.n for g in grains])
    edges = [g.edges + first[k] for k, g in enumerate(grains)]
    cond = [lam * g.factor for g in grains]
    contacts = {}
    centres = [g.placed(*p) for g, p in zip(grains, poses)]
    reach = [float(np.max(np.linalg.norm(c - c.mean(axis=0), axis=1)) + g.radii.max()) for c, g in
             zip(centres, grains)]
    for i in range(len(grains)):
        for j in range(i + 1, len(grains)):
            if np.linalg.norm(centres[i].mean(axis=0) - centres[j].mean(axis=0)) > reach[i] + reach[j]:
                continue
            pairs, G, area = grain_contact(grains[i], poses[i], grains[j], poses[j], resistance, lam, samples)
            if pairs.size:
                edges.append(np.column_stack([pairs[:, 0] + first[i], pairs[:, 1] + first[j]]))
                cond.append(G)
                contacts[(i, j)] = area
    C = float(rho_c) * np.concatenate([g.volume for g in grains])
    return np.concatenate(edges), np.concatenate(cond), C, first[:-1], contacts
