"""What the steps need of the scene, judged before any work (``catdae run`` and ``catdae
check``): inertia at every free node of a transient, stiffness at every node a damper reaches,
a support for every part of the scene a static or modal step must balance, and no sweep of a
form-finding step."""

from __future__ import annotations

import numpy as np

from catdae.case import AXES, Case
from catdae.errors import CaseError
from catdae.model import formfind
from catdae.model.assembly import Model


def check_steps(case: Case, mesh) -> None:
    """What the steps need of the scene, judged before any work (``catdae check`` too).

    A transient step needs inertia at every free node: with no mass there (a massless cable,
    no point mass) M(q) is singular and the accelerations undefined (they came out NaN).
    Raises CaseError with the step's field path.
    """
    problems = []
    if case.steps and case.steps[0].sweep is not None and formfind.pending(case):
        problems.append(("steps[0].sweep", "the first static step finds the cables' lengths "
                         "(form-finding) and cannot be swept; sweep a later step"))
    problems += _damper_only_nodes(case, mesh)
    problems += _unheld_parts(case, mesh)
    fixed = {n for n, axes in case.supports.items() if len(axes) == len(AXES)}
    if all(n in fixed for n in mesh.node_names):  # nothing can move: no modes, no motion
        problems += [(f"steps[{i}]", f"{s.kind} step '{s.name}': the model has no free degree "
                      "of freedom (every node is a fully fixed support; a cable of one element "
                      "between two supports has no node of its own): give the cables 2 or more "
                      "elements") for i, s in enumerate(case.steps) if s.kind != "static"]
    absent = {x.name for x in (*case.point_masses, *case.loads, *case.distributed_loads)
              if not x.active}
    for i, step in enumerate(case.steps):
        absent = (absent - set(step.add)) | set(step.remove)
        if step.kind != "transient":
            continue
        model = Model(case, mesh, absent, mass_model=step.mass_model, kind=step.kind)
        massless = model.lumped_mass_diag().reshape(-1, 3)[:, 0] <= 0.0
        free = ~model.fixed_mask.all(axis=1)
        nodes = np.flatnonzero(massless & free)
        names = [mesh.node_names[k] for k in nodes]
        if names:
            shown = ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5
                                            else "")
            on_cable = bool((mesh.cable_of_node[nodes] >= 0).any())
            problems.append((f"steps[{i}]", f"transient step '{step.name}': free node(s) "
                             f"{shown} have no mass, so no acceleration is defined: "
                             + ("give the cable's material a mass > 0 or put a point mass "
                                "there" if on_cable else "put a point mass there (no cable "
                                "reaches it), or support it")))
    if problems:
        raise CaseError(case.path, problems)


def _damper_only_nodes(case: Case, mesh) -> list[tuple[str, str]]:
    """Free nodes that dampers reach but nothing stiff (no cable element, spring or bar):
    without stiffness they have no static equilibrium (the modal step then failed with "not
    stable", naming nothing)."""
    if not case.dampers:
        return []
    model = Model(case, mesh, set())
    cn = model.connectors
    stiff = np.zeros(mesh.n_nodes, bool)
    stiff[mesh.conn.ravel()] = True
    held = np.array([kind != "damper" and k > 0 for kind, k in zip(cn.kinds, cn.stiffness,
                                                                   strict=True)], bool)
    stiff[cn.ends[held].ravel()] = True
    free = ~model.fixed_mask.all(axis=1)
    out = []
    for i, d in enumerate(case.dampers):
        loose = [e for e in d.ends if free[mesh.node_index(e)] and not stiff[mesh.node_index(e)]]
        out += [(f"dampers[{i}].ends", f"node {e!r} is held by the damper alone (no cable, "
                 "spring or bar reaches it, and it is not a support): a damper has no "
                 "stiffness, so the node has no static equilibrium; support it, or join it "
                 "with a spring or a bar") for e in loose]
    return out


def _unheld_parts(case: Case, mesh) -> list[tuple[str, str]]:
    """Parts of the scene (nodes joined by cables, springs and bars) with no support, when a
    static or modal step must balance them: they have no equilibrium, and the step failed late
    (200 Newton iterations, "ramped up to 0 %"; or "not stable") without naming them. A
    transient alone may let a part fall on purpose; a seabed may hold what rests on it."""
    if case.seabed is not None or not any(s.kind in ("static", "modal") for s in case.steps):
        return []
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    joins = [[mesh.node_index(e) for e in c.ends] for c in (*case.springs, *case.bars)]
    pairs = np.vstack([mesh.conn, np.array(joins, np.int64).reshape(-1, 2)])
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                       shape=(mesh.n_nodes, mesh.n_nodes))
    part_of = connected_components(graph, directed=False)[1]
    held = {int(part_of[mesh.node_index(n)]) for n, axes in case.supports.items() if axes}
    out = []
    for i, c in enumerate(case.cables):
        part = int(part_of[mesh.node_index(c.ends[0])])
        if part in held:
            continue
        held.add(part)  # say it once per part
        names = [x.name for x in case.cables if part_of[mesh.node_index(x.ends[0])] == part]
        shown = ", ".join(repr(n) for n in names[:5]) + (
            f" and {len(names) - 5} more" if len(names) > 5 else "")
        out.append((f"cables[{i}]", f"cable{'s' if len(names) > 1 else ''} {shown}: no support "
                    "holds {} directly or through other cables, springs or bars, so a static or "
                    "modal step has no equilibrium; support a node of it, or join it to a "
                    "supported part".format("them" if len(names) > 1 else "it")))
    return out
