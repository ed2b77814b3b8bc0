"""What the steps need of the scene, judged before any work (``catdae run`` and ``catdae
check``): inertia at every free node of a transient, stiffness at every node a damper reaches,
and no sweep of a form-finding step."""

from __future__ import annotations

import numpy as np

from catdae.case import Case
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
    absent = {x.name for x in (*case.point_masses, *case.loads, *case.distributed_loads)
              if not x.active}
    for i, step in enumerate(case.steps):
        absent = (absent - set(step.add)) | set(step.remove)
        if step.kind != "transient":
            continue
        model = Model(case, mesh, absent, mass_model=step.mass_model, kind=step.kind)
        massless = model.lumped_mass_diag().reshape(-1, 3)[:, 0] <= 0.0
        free = ~model.fixed_mask.all(axis=1)
        names = [mesh.node_names[k] for k in np.flatnonzero(massless & free)]
        if names:
            shown = ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5
                                            else "")
            problems.append((f"steps[{i}]", f"transient step '{step.name}': free node(s) "
                             f"{shown} have no mass, so no acceleration is defined: give the "
                             "cable's material a mass > 0 or put a point mass there"))
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
