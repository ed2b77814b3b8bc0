"""The pipeline: case -> mesh -> one model per step -> solver -> labelled results.

The state (node positions, velocities, element tensions) flows from step to step. A failing step
keeps everything computed before it: the exception carries the partial result tree in
``partial`` and its status says why.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import xarray as xr

from . import results
from .assembly import Model
from .case import Case, Step, load_case
from .element import NOT_CONVERGED
from .errors import CatdaeError, ConvergenceError
from .mesh import build_mesh
from .modal import solve_modal
from .static import solve_static


class _State:
    """What passes between steps."""

    def __init__(self, X: np.ndarray):
        self.X = X  # (n_nodes, 3) m
        self.V = np.zeros_like(X)  # (n_nodes, 3) m/s
        self.h: np.ndarray | None = None  # (n_elem, 3) N, warm start
        self.t = 0.0


def as_case(case_or_path: Case | str | os.PathLike) -> Case:
    return case_or_path if isinstance(case_or_path, Case) else load_case(case_or_path)


def run(case_or_path: Case | str | os.PathLike, *, output: str | os.PathLike | None = None,
        progress: bool | None = None, on_group: Callable[[str, xr.Dataset], None] | None = None,
        **overrides) -> xr.DataTree:
    """Run every step of a case and return an ``xarray.DataTree`` with one group per step.

    ``overrides`` (rtol, atol, elements, mass_model) replace the case's values. With
    ``output`` the tree is also written to netCDF-4; long transient steps write it in
    increments as they go. On failure a CatdaeError is raised whose ``partial`` attribute
    holds the tree computed so far (status says why); with ``output`` that partial tree is
    written too, never over an existing file (it goes to ``<output stem>.failed.nc`` then).
    """
    case = as_case(case_or_path)
    ov = {k: v for k, v in overrides.items() if v is not None}
    if ov:
        case = case.with_overrides(**ov)
    mesh = build_mesh(case)
    state = _State(mesh.X0.copy())
    groups: dict[str, xr.Dataset] = {}
    steps = case.steps or (Step(kind="static", name="static"),)
    # what a step leaves out: the items not yet added (active = false) and those removed
    absent = {x.name for x in (*case.point_masses, *case.loads, *case.distributed_loads)
              if not x.active}
    writer = _Writer(case, output, groups)
    for step in steps:
        absent = (absent - set(step.add)) | set(step.remove)
        model = Model(case, mesh, absent, mass_model=step.mass_model)
        try:
            ds = _run_step(step, model, state, writer, progress)
        except KeyboardInterrupt:
            # keep what the finished steps computed; the interrupt itself goes on
            tree = results.make_tree(case, groups,
                                     status=f"interrupted in step '{step.name}'")
            writer.write_failed(tree)
            raise
        except CatdaeError as exc:
            ds_partial = getattr(exc, "partial", None)
            if isinstance(ds_partial, xr.Dataset):
                groups[step.name] = ds_partial
            status = f"failed in step '{step.name}': {exc}"
            tree = results.make_tree(case, groups, status=status)
            exc.partial = tree
            exc.output_path = writer.write_failed(tree)
            raise
        groups[step.name] = ds
        if on_group is not None:
            on_group(step.name, ds)
    tree = results.make_tree(case, groups)
    writer.write_final(tree)
    return tree


def _run_step(step: Step, model: Model, state: _State, writer, progress) -> xr.Dataset:
    if step.kind == "static":
        return _static_step(step, model, state)
    if step.kind == "modal":
        return _modal_step(step, model, state)
    from .transient import run_transient  # the only module that imports sksundae

    return run_transient(step, model, state, writer, progress)


def _static_step(step: Step, model: Model, state: _State) -> xr.Dataset:
    sol = solve_static(model, state.X, state.h, t=state.t, load_steps=step.load_steps)
    state.X, state.h = sol.X, sol.state.h
    state.V = np.zeros_like(sol.X)
    return results.static_dataset(
        model.mesh, sol.X, model.tensions(sol.state), model.reactions(sol.state, state.t),
        {"iterations": sol.iterations, "residual_norm": sol.residual_norm,
         "load_increments": sol.load_steps, "status": "completed"},
        cables=model.cable_summary(sol.X, sol.state),
    )


def _modal_step(step: Step, model: Model, state: _State) -> xr.Dataset:
    model.set_time(state.t)
    est = model.element_state(state.X, state.h)
    if (est.status == NOT_CONVERGED).any():
        raise ConvergenceError(f"modal step '{step.name}': an element cannot be solved in the "
                               "current configuration")
    sol = solve_modal(model, state.X, est, step.modes)
    return results.modal_dataset(model.mesh, sol.frequency, sol.shape, sol.plane, sol.symmetry,
                                 {"solver": sol.solver, "mass_model": model.mass_model,
                                  "status": "completed"})


class _Writer:
    """Writes the tree to ``output``: in increments during long steps, atomically at the end."""

    def __init__(self, case: Case, output, groups: dict[str, xr.Dataset]):
        self.case = case
        self.output = Path(output) if output is not None else None
        self.groups = groups
        self.existed = self.output is not None and self.output.exists()

    @property
    def partial_path(self) -> Path | None:
        if self.output is None:
            return None
        return self.output.with_name(self.output.stem + ".partial.nc")

    def write_increment(self, name: str, ds: xr.Dataset) -> None:
        """A readable snapshot of the run so far, beside the output (never over it)."""
        if self.output is None:
            return
        tree = results.make_tree(self.case, {**self.groups, name: ds},
                                 status=f"running step '{name}'")
        results.write_tree(tree, self.partial_path)

    def write_final(self, tree: xr.DataTree) -> None:
        if self.output is None:
            return
        results.write_tree(tree, self.output)
        if self.partial_path.exists():
            self.partial_path.unlink()

    def write_failed(self, tree: xr.DataTree) -> Path | None:
        if self.output is None:
            return None
        target = self.output
        if self.existed or target.exists():
            target = self.output.with_name(self.output.stem + ".failed.nc")
        results.write_tree(tree, target)
        if self.partial_path.exists():
            self.partial_path.unlink()
        return target
