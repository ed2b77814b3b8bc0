"""Gravity along any direction: the scene is solved in a frame where gravity acts along -z.

The element kernel (docs/theory.md §1-2) carries the weight along its -z axis: the tension
vector is ``t(s) = h + (0, 0, w s) - Σ f_k``. A case whose ``gravity`` is a vector ``g`` is
rotated, as a rigid body, into the frame where ``g`` points along -z; it is solved there and its
vector results are rotated back. A rotation changes nothing physical, so this is exact.

The rotation ``R`` (local = R global) has third row ``-ĝ``. Its first two rows are taken, where
possible, from global axes perpendicular to ``ĝ`` (all of them when ``ĝ`` lies along an axis),
so that supports fixing only some axes still fix coordinate axes in the rotated frame. A support
whose fixed axes do not map onto local coordinate axes is rejected by the case validation
(:func:`local_axes`).

The fluids and the seabed are given in "up" = -ĝ already (heights along up: the still-water
``surface``, ``depth``, a current profile's ``z``, the wind's ``ground``, the seabed's ``z``;
headings and wind directions in the plane normal to ``g``, from the first row of ``R`` towards
the second): those stay as they are in the rotated frame, whose z is that height. Only the
velocity vectors (current, wind), given in global axes, are rotated.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from catdae.case.model import AXES, Case, SupportMotion
from catdae.case.timefunc import TimeFunction

_TOL = 1e-12


def gravity_rotation(direction) -> np.ndarray:
    """The proper rotation (3, 3) taking the unit vector ``direction`` to -z."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    r3 = -d
    free = [np.eye(3)[a] for a in range(3) if abs(d[a]) <= _TOL]
    if free:
        r1 = free[0]
    else:  # the axis most nearly perpendicular to gravity, projected on the horizontal plane
        a = int(np.argmin(np.abs(d)))
        e = np.eye(3)[a]
        r1 = e - (e @ r3) * r3
        r1 /= np.linalg.norm(r1)
    r2 = np.cross(r3, r1)
    R = np.array([r1, r2, r3])
    R[np.abs(R) <= _TOL] = 0.0
    return R


def local_axes(R: np.ndarray, axes: tuple[str, ...]) -> tuple[str, ...] | None:
    """The local axes spanning the same subspace as the global ``axes``, or None if none do."""
    cols = [AXES.index(a) for a in axes]
    rows = sorted({b for b in range(3) for a in cols if abs(R[b, a]) > _TOL})
    return tuple(AXES[b] for b in rows) if len(rows) == len(cols) else None


@dataclass(frozen=True)
class Combination(TimeFunction):
    """``f(t) = Σ c_i f_i(t)``: one local axis of a rotated support motion."""

    terms: tuple[tuple[float, TimeFunction], ...] = ()

    def _evaluate(self, t):
        f = df = d2f = 0.0
        for c, fn in self.terms:
            a, b, e = fn.evaluate(t)
            f, df, d2f = f + c * a, df + c * b, d2f + c * e
        return f, df, d2f

    def breakpoints(self) -> tuple[float, ...]:
        return tuple(sorted({b for _, fn in self.terms for b in fn.breakpoints()}))


def to_gravity_frame(case: Case) -> tuple[Case, np.ndarray | None]:
    """``(case in the frame where gravity is -z, R)``; ``R`` is None when it already is."""
    R = gravity_rotation(case.gravity_direction)
    if np.array_equal(R, np.eye(3)):
        return case, None

    def rot(v):
        return tuple(float(x) for x in R @ np.asarray(v, float))

    supports = {n: local_axes(R, ax) for n, ax in case.supports.items()}
    motions = []
    for sm in case.support_motions:
        funcs = {}
        for b, name in enumerate(AXES):
            terms = tuple((float(R[b, AXES.index(a)]), f) for a, f in sm.moved()
                          if R[b, AXES.index(a)] != 0.0)
            if terms:
                funcs[name] = (terms[0][1] if terms == ((1.0, terms[0][1]),)
                               else Combination(terms))
        motions.append(SupportMotion(sm.node, **funcs))
    local = replace(
        case, gravity_direction=(0.0, 0.0, -1.0),
        nodes={n: rot(x) for n, x in case.nodes.items()}, supports=supports,
        loads=tuple(replace(ld, force=rot(ld.force)) for ld in case.loads),
        distributed_loads=tuple(replace(d, load=rot(d.load)) for d in case.distributed_loads),
        support_motions=tuple(motions), water=_water(case.water, rot),
        air=_air(case.air, rot),
    )
    return local, R


def _water(water, rot):
    """The water in the rotated frame: the current's velocities rotated; its heights (along
    up), the surface, depth and waves (headings in the frame's x-y plane) as they are."""
    if water is None or water.current is None:
        return water
    cur = water.current
    return replace(water, current=replace(cur, velocity=tuple(rot(u) for u in cur.velocity)))


def _air(air, rot):
    """The air in the rotated frame: the wind's velocity rotated (its ground is a height)."""
    if air is None or air.wind is None:
        return air
    return replace(air, wind=replace(air.wind, vector=rot(air.wind.vector)))


def rotate_back(ds, R: np.ndarray | None):
    """Every variable with an ``axis`` dimension (last) rotated from the local to the global
    frame: v = Rᵀ v_local. A NaN component (a reaction on an axis a support leaves free) stays
    NaN only on the global axes it reaches; a mode shape is scaled again to a largest component
    of +1 in the case's axes; the ``axis`` label says the axes are the case's."""
    if R is None:
        return ds
    out = ds.copy()
    for name, var in ds.data_vars.items():
        if var.dims and var.dims[-1] == "axis":
            v = np.asarray(var.values)
            nan = np.isnan(v)
            g = np.where(nan, 0.0, v) @ R
            if nan.any():
                g[(nan.astype(float) @ (np.abs(R) > _TOL)) > 0] = np.nan
            if name == "shape":  # (..., mode, node, axis): the largest component +1 again
                g = _largest_one(g)
            elif name == "complex_shape":  # (..., mode, part, node, axis), part = real, imag
                z = _largest_one(g[..., 0, :, :] + 1j * g[..., 1, :, :])
                g = np.stack([z.real, z.imag], axis=-3)
            out[name] = var.copy(data=g)
    if "axis" in out.coords:
        out.coords["axis"].attrs["long_name"] = "axis of the case (gravity along the group's -up)"
    return out


def _largest_one(g: np.ndarray) -> np.ndarray:
    """Shapes (..., node, axis), real or complex, each divided by its component of largest
    modulus (a sweep adds leading dimensions); a shape of NaN (a mode not found) stays NaN."""
    flat = g.reshape(-1, g.shape[-2] * g.shape[-1])
    mag = np.where(np.isnan(flat), -1.0, np.abs(flat))
    big = flat[np.arange(flat.shape[0]), np.argmax(mag, axis=1)]
    big = np.where((big == 0) | np.isnan(big), 1.0, big)
    return (flat / big[:, None]).reshape(g.shape)
