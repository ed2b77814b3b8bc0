"""Seabed results of a static step (docs/case-format.md, "Seabed"): per cable, the unstrained
length resting on the seabed and the touchdown point."""

from __future__ import annotations

import numpy as np

from catdae._xr import xr
from catdae.model.seabed import ends_on_seabed
from catdae.output.results import label, var


def add_seabed(ds: xr.Dataset, mesh, summary: dict) -> xr.Dataset:
    """``ds`` with ``seabed_length``(cable) and ``touchdown``(cable, axis)."""
    if "cable" not in ds.coords:
        ds = ds.assign_coords(cable=label("cable", mesh.cable_names, "cable name"))
    ds["seabed_length"] = var("cable", summary["seabed_length"], "m",
                               "unstrained length of cable resting on the seabed")
    ds["touchdown"] = var(("cable", "axis"), summary["touchdown"], "m",
                           "touchdown point: where the cable leaves the seabed (NaN: none)")
    return ds


SAG_SHARE = 0.05  # of an element's length: a sag into the seabed between nodes worth a word


def static_seabed_note(ds: xr.Dataset, mesh, seabed) -> str:
    """What a static step on the seabed's contact springs says: a cable sagging into them
    (:func:`sag_into_seabed`), and that its friction was left out (a static state with
    Coulomb friction is not unique: the frictionless one is given; docs/case-format.md)."""
    said = [sag_into_seabed(ds, mesh, seabed.z)]
    if seabed.friction_axial > 0.0 or seabed.friction_lateral > 0.0:
        said.append("the seabed's friction is left out of static steps: this static state is "
                    "the frictionless one (with Coulomb friction a resting line has a "
                    "whole set of equilibria; the anchor tension is not reduced by friction "
                    "here)")
    return "; ".join(x for x in said if x)


def sag_into_seabed(ds: xr.Dataset, mesh, zb: float) -> str:
    """A note ("" when none) for a static state on contact springs in which a cable's lowest
    point hangs below the seabed and below its lowest node by more than SAG_SHARE of its
    longest element: the springs act at the nodes only, so an element resting on the seabed
    with little tension sags into it between them (docs/accuracy.md), and a lying line with a
    free end folds into loops (an independent tester's 100 m chain: every node on its pinned
    end)."""
    if "lowest_point_elevation" not in ds or "cable" not in ds.coords:
        return ""
    z = ds.position.sel(axis="z", node=list(mesh.node_names)).values  # in mesh order
    worst = None
    for c, name in enumerate(mesh.cable_names):
        low = float(ds.lowest_point_elevation.sel(cable=name))
        els = mesh.cable_of_element == c
        node_low = float(z[mesh.conn[els]].min())
        depth = node_low - low
        if low < zb and depth > SAG_SHARE * float(mesh.L0[els].max()):
            if worst is None or depth > worst[1]:
                worst = (name, depth, low, zb - node_low)
    if worst is None:
        return ""
    name, depth, low, pen = worst
    return (f"cable {name!r} hangs to z = {low:.4g} m, {depth:.3g} m below its lowest node "
            f"(which sinks {pen:.3g} m into the seabed's springs): the contact springs act at "
            "the nodes only, so elements lying on the seabed with little tension sag into it "
            "between them, and a lying line with a free end folds into loops; for statics use "
            "the rigid seabed (no stiffness), or many more elements (docs/accuracy.md)")


def add_seabed_history(ds: xr.Dataset, mesh, zb: float, contact=None) -> xr.Dataset:
    """A transient group with ``seabed_length``(time, cable) and ``touchdown``(time, cable,
    axis) at node resolution, from the node positions: free nodes at or below the seabed are in
    contact; an element counts whole with both ends in contact, half with one (a support at
    the seabed only with its neighbour: catdae.model.seabed.ends_on_seabed); the touchdown
    is the last node in contact seen from the cable's upper end (the higher end at that time;
    NaN when that end itself rests on the seabed), as in the static groups."""
    if "position" not in ds or "time" not in ds.dims:
        return ds
    z = ds.position.sel(axis="z").transpose("time", "node").values  # (nt, n_nodes)
    order = [list(ds.node.values).index(n) for n in mesh.node_names]
    on = z[:, order] <= zb + 1e-9 * max(1.0, abs(zb))  # (nt, n_nodes) in mesh order
    held = ~np.isnan(ds.reaction.sel(axis="z").transpose("time", "node").values[:, order])
    anchor = on & held  # supports at the seabed: laid only with their neighbour
    on &= ~held
    n_on = ends_on_seabed(on, anchor, mesh.conn)  # (nt, n_elem)
    nc = len(mesh.cable_names)
    length = np.stack([(0.5 * n_on[:, mesh.cable_of_element == c] *
                        mesh.L0[mesh.cable_of_element == c]).sum(axis=1) for c in range(nc)],
                      axis=1)
    pos = ds.position.transpose("time", "node", "axis").values[:, order]
    td = np.full((z.shape[0], nc, 3), np.nan)
    rows = np.arange(z.shape[0])
    for c in range(nc):
        els = np.flatnonzero(mesh.cable_of_element == c)
        a, b = mesh.conn[els, 0], mesh.conn[els, 1]
        touch = on[:, a] | on[:, b]  # (nt, elements of the cable): a node in contact
        up_last = z[:, order][:, b[-1]] >= z[:, order][:, a[0]]  # walk from the upper end
        k = touch.shape[1]
        first = np.where(up_last, k - 1 - touch[:, ::-1].argmax(axis=1), touch.argmax(axis=1))
        node = np.where(on[rows, a[first]], a[first], b[first])  # its end in contact
        has = (touch.any(axis=1) & (on[rows, a[first]] != on[rows, b[first]])
               & (length[:, c] > 0.0))
        td[has, c] = pos[rows[has], node[has]]
    if "cable" not in ds.coords:
        ds = ds.assign_coords(cable=label("cable", mesh.cable_names, "cable name"))
    ds["seabed_length"] = var(("time", "cable"), length, "m",
                               "unstrained length of cable resting on the seabed")
    ds["touchdown"] = var(("time", "cable", "axis"), td, "m",
                           "touchdown point: where the cable leaves the seabed (NaN: none)")
    if contact is not None:  # the power the seabed's damping and friction take out, and its work
        vel = ds.velocity.transpose("time", "node", "axis").values[:, order]
        power = np.array([contact.dissipation(pos[k], vel[k]) for k in range(z.shape[0])])
        t = ds.time.values
        work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
        ds["seabed_dissipation"] = var("time", power, "W",
                                        "power taken out by the seabed's damping and friction")
        ds["seabed_work"] = var("time", work, "J", "energy taken out by the seabed's damping "
                                 "and friction since the step's start (trapezoidal rule)")
    return ds
