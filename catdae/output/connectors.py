"""Result variables of the connectors and of damped modes (docs/case-format.md, Results).

Added to a step's dataset only when the scene has connectors (``connector_force``) or damping
(the damped modes of a modal step); a scene without them gets exactly the dataset it had.
"""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.output.results import label, var, with_note


def with_connector_forces(ds: xr.Dataset, connectors, X: np.ndarray,
                          V: np.ndarray | None = None) -> xr.Dataset:
    """``connector_force`` (N, tension positive) and ``connector_swing_angle`` (degrees,
    :func:`swing_angles`) from positions X (..., n_nodes, 3) in the gravity frame and
    velocities V (same shape, or None: at rest); a leading ``time`` axis when X has one."""
    if connectors is None:
        return ds
    X = np.asarray(X)
    lead = X.shape[:-2]
    flat_x = X.reshape(-1, *X.shape[-2:])
    flat_v = None if V is None else np.asarray(V).reshape(flat_x.shape)
    N = np.array([connectors.axial_force(flat_x[k], None if flat_v is None else flat_v[k])
                  for k in range(flat_x.shape[0])]).reshape(*lead, connectors.n)
    dims = ("time", "connector") if lead else ("connector",)
    return ds.assign(
        connector_force=var(dims, N, "N", "axial force of the connector (tension positive): "
                             "k (d - L) + c dd/dt"),
        connector_swing_angle=var(dims, swing_angles(connectors, X), "degree",
                                   "angle of the connector's axis (end a to end b) from the "
                                   "vertical line (0: hanging or standing straight; NaN for a "
                                   "damper)"),
        connector_axis=var((*dims, "axis"), unit_axes(connectors, X), "1",
                           "unit vector along the connector from end a to end b (its "
                           "horizontal part: the side a string swings to)"),
    ).assign_coords(
        connector=label("connector", connectors.names, "connector name"),
        connector_kind=label("connector", connectors.kinds, "spring, damper or bar"),
        connector_node=label(("connector", "end"), np.asarray(ds.node.values)[connectors.ends],
                             "nodes at the connector's ends"),
    )


def like_undamped(undamped: np.ndarray, damped: np.ndarray, n: int) -> np.ndarray:
    """For each damped mode (complex shapes (k, n_nodes, 3)), the number (from 1) of the
    undamped mode (real shapes (n, n_nodes, 3)) paired with it one to one on the modal
    assurance criterion |uᵀ φ|² / (|u|² |φ|²) (the pairs of largest total); 0 beyond the k
    found. Damped modes are sorted by |s| and the
    overdamped ones dropped, so the k-th damped mode need not be the k-th undamped one."""
    out = np.zeros(n, dtype=np.int32)
    if damped.shape[0] == 0 or undamped.shape[0] == 0:  # none found underdamped
        return out
    u = np.nan_to_num(undamped.reshape(undamped.shape[0], -1))
    d = np.nan_to_num(damped.reshape(damped.shape[0], -1))[:n]
    num = np.abs(d.conj() @ u.T) ** 2
    den = np.outer(np.einsum("ij,ij->i", d.conj(), d).real, np.einsum("ij,ij->i", u, u))
    mac = num / np.where(den > 0, den, 1.0)
    # one to one (Hungarian): two stays joined by a strong damper have damped modes that mix
    # undamped ones, and the largest criterion of each mapped two of them to one mode (t68)
    from scipy.optimize import linear_sum_assignment

    rows, cols = linear_sum_assignment(-mac)
    out[rows] = cols + 1
    return out


def unit_axes(connectors, X: np.ndarray) -> np.ndarray:
    """Each connector's unit vector from end a to end b (..., n, 3) (NaN where they meet)."""
    d = X[..., connectors.ends[:, 1], :] - X[..., connectors.ends[:, 0], :]
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length > 0, d / length, np.nan)


def swing_angles(connectors, X: np.ndarray) -> np.ndarray:
    """The angle of each spring's and bar's axis from the vertical line, degrees in [0, 90]
    (atan of its horizontal length over its vertical one; an insulator string's swing: under a
    lateral load P and a vertical load W at its lower end, tan θ = P / W), (..., n); NaN for
    dampers. X (..., n_nodes, 3) in the gravity frame (z up, catdae.case.frame)."""
    X = np.asarray(X)
    d = X[..., connectors.ends[:, 1], :] - X[..., connectors.ends[:, 0], :]  # (..., n, 3) m
    angle = np.degrees(np.arctan2(np.hypot(d[..., 0], d[..., 1]), np.abs(d[..., 2])))
    return np.where(np.array(connectors.kinds) == "damper", np.nan, angle)


def with_damped_modes(ds: xr.Dataset, modes, shapes: np.ndarray, plane, symmetry
                      ) -> xr.Dataset:
    """The damped modes of a modal step beside its undamped results: ``frequency`` becomes the
    damped frequency, the undamped one is kept as ``undamped_frequency``; ``damping_ratio``,
    ``eigenvalue_real``/``eigenvalue_imag`` and ``complex_shape`` per mode (NaN for modes
    beyond those found underdamped)."""
    n = ds.sizes["mode"]
    k = min(n, modes.s.size)

    def pad(values, fill=np.nan):
        out = np.full((n, *np.shape(values)[1:]), fill, dtype=np.result_type(values, float))
        out[:k] = values[:k]
        return out

    shape = pad(np.stack([shapes.real, shapes.imag], axis=1))  # (n, 2, n_nodes, 3)
    labels = ["overdamped or not found"] * n
    ds = with_note(ds, getattr(modes, "note", ""))
    if k < n:  # a mode without oscillation has a real eigenvalue: no frequency, no ζ < 1
        ds = with_note(ds, f"{n - k} of the {n} modes asked for are overdamped (damped beyond "
                       "critical: they decay without oscillating) or were not found: their "
                       "damped results are NaN, labelled so")
    return ds.assign(
        undamped_mode=var("mode", like_undamped(ds["shape"].values, shapes, n), "1",
                          "number of the undamped mode the damped mode is most like (MAC); "
                          "0: not found"),
        undamped_frequency=ds["frequency"].assign_attrs(
            long_name="natural frequency of the undamped system"),
        frequency=var("mode", pad(modes.frequency), "Hz",
                       "damped natural frequency Im(s)/2π"),
        damping_ratio=var("mode", pad(modes.damping_ratio), "1",
                           "modal damping ratio -Re(s)/|s|"),
        eigenvalue_real=var("mode", pad(modes.s.real), "1/s", "Re(s) of the damped mode"),
        eigenvalue_imag=var("mode", pad(modes.s.imag), "rad/s", "Im(s) of the damped mode"),
        complex_shape=var(("mode", "part", "node", "axis"), shape, "1",
                           "complex shape of the damped mode (largest component = 1)"),
        damped_plane=label("mode", list(plane[:k]) + labels[k:],
                            "plane of the damped mode (from the real part of its shape)"),
        damped_symmetry=label("mode", list(symmetry[:k]) + labels[k:],
                               "symmetry of the damped mode (from the real part of its shape)"),
    ).assign_coords(part=label("part", ["real", "imag"], "part of the complex shape"))
