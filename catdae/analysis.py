"""The pipeline: case -> mesh -> one model per step -> solver -> labelled results.

The state (node positions, velocities, element tensions) flows from step to step. A failing step
keeps everything computed before it: the exception carries the partial result tree in
``partial`` and its status says why.
"""

from __future__ import annotations

import copy
import os
import traceback
from collections.abc import Callable, Mapping
from contextlib import suppress

import numpy as np

from catdae._xr import xr
from catdae.case import Case, Step, load_case
from catdae.case.frame import rotate_back, to_gravity_frame
from catdae.case.sweep import apply_sweep
from catdae.case.sweep import units as sweep_units
from catdae.element.elements import NOT_CONVERGED
from catdae.errors import CatdaeError, ConvergenceError, InternalError, OutOfMemory
from catdae.model import formfind
from catdae.model.assembly import Model
from catdae.model.checks import check_steps
from catdae.model.fluid import plausibility_note
from catdae.model.mesh import build_mesh
from catdae.model.snap import snap_reason
from catdae.model.span import span_quantities
from catdae.output import engineering, results
from catdae.output.connectors import with_connector_forces, with_damped_modes
from catdae.output.fluid import effective_tension, with_static_fluid
from catdae.output.reading import join_values, per_value
from catdae.output.transient import as_dataset
from catdae.output.writer import ResultWriter
from catdae.solvers.damped_modes import solve_damped
from catdae.solvers.modal import classify, solve_modal
from catdae.solvers.static import solve_static


class _State:
    """What passes between steps."""

    def __init__(self, X: np.ndarray):
        self.X = X  # (n_nodes, 3) m
        self.V = np.zeros_like(X)  # (n_nodes, 3) m/s
        self.h: np.ndarray | None = None  # (n_elem, 3) N, warm start
        self.snap = ""  # the step that took the lumped mass for a snap (auto), if the last
        self.t = 0.0
        self.unbalanced = False  # after a sweep: a modal step finds its own equilibrium


def as_case(case_or_path: Case | str | os.PathLike, elements: int | None = None) -> Case:
    """A Case as given, or read from a path or text (``elements``: judged on that mesh)."""
    if isinstance(case_or_path, Case):
        return case_or_path if elements is None else case_or_path.with_overrides(
            elements=elements)
    return load_case(case_or_path, elements=elements)


OVERRIDES = ("rtol", "atol", "elements", "mass_model", "max_order")  # Case.with_overrides


def run(case_or_path: Case | str | os.PathLike, *, output: str | os.PathLike | None = None,
        progress: bool | None = None, on_group: Callable[[str, xr.Dataset], None] | None = None,
        **overrides) -> xr.DataTree:
    """Run every step of a case and return an ``xarray.DataTree`` with one group per step.

    ``overrides`` (rtol, atol, elements, mass_model, max_order) replace the case's values. With
    ``output`` the tree is also written to netCDF-4; long transient steps write it in
    increments as they go. On failure a CatdaeError is raised whose ``partial`` attribute
    holds the tree computed so far (status says why); with ``output`` that partial tree is
    written too, never over an existing file (it goes to ``<output stem>.failed.nc`` then).
    """
    unknown = sorted(set(overrides) - set(OVERRIDES))
    if unknown:
        raise TypeError(f"catdae.run() got an unexpected keyword argument {unknown[0]!r}; it "
                        f"takes output, progress, on_group and the overrides "
                        f"{', '.join(OVERRIDES)}")
    ov = {k: v for k, v in overrides.items() if v is not None}
    case = as_case(case_or_path, ov.pop("elements", None))
    if ov:
        case = case.with_overrides(**ov)
    # solved where gravity is -z (catdae.case.frame); vector results are rotated back
    local, rotation = to_gravity_frame(case)
    local = formfind.initial_lengths(local)  # form-found lengths: a start
    find_forms = bool(formfind.pending(local))
    mesh = build_mesh(local)
    check_steps(local, mesh)
    state = _State(mesh.X0.copy())
    groups: dict[str, xr.Dataset] = {}
    steps = case.steps or (Step(kind="static", name="static"),)
    # what a step leaves out: the items not yet added (active = false) and those removed
    absent = {x.name for x in (*case.point_masses, *case.loads, *case.distributed_loads)
              if not x.active}
    temperature: float | dict = 0.0
    writer = ResultWriter(case, output, groups, rotation)
    for step in steps:
        absent = (absent - set(step.add)) | set(step.remove)
        if step.temperature_change is not None:
            temperature = step.temperature_change
        try:
            if find_forms and step.kind == "static":
                local, mesh, model, ds = _form_step(step, local, absent, temperature, state)
                find_forms = False
            elif step.sweep is not None:
                ds, temperature = _sweep_step(step, local, mesh, absent, temperature, state,
                                              progress)
            else:
                model = step_model(local, mesh.heated(local, temperature), absent, step,
                                   state)
                ds = _run_step(step, model, state, writer, progress)
            ds = engineering_results(step, rotate_back(ds, rotation), case, groups,
                                     temperature)
        except KeyboardInterrupt as exc:
            # keep what the finished steps (and a transient, up to the interrupt) computed;
            # the interrupt itself goes on
            ds_partial = as_dataset(getattr(exc, "partial", None))
            status = f"interrupted in step '{step.name}'"
            if isinstance(ds_partial, xr.Dataset):
                groups[step.name] = _partial(step, rotate_back(ds_partial, rotation), case,
                                             groups, temperature, on_group)
                status += f": {ds_partial.attrs.get('status')}"
            writer.keep_failed(exc, results.make_tree(case, groups, status=status))
            raise
        except MemoryError as exc:  # a step failure like any other: what was computed is kept
            if exc.__traceback__ is not None:  # free the failed step's arrays before writing
                traceback.clear_frames(exc.__traceback__)
            del exc
            err = OutOfMemory.in_step(step.name)
            status = f"failed in step '{step.name}': {err}"
            writer.keep_failed(err, results.make_tree(case, groups, status=status))
            raise err from None
        except CatdaeError as exc:
            ds_partial = as_dataset(getattr(exc, "partial", None))
            if isinstance(ds_partial, xr.Dataset):
                groups[step.name] = _partial(step, rotate_back(ds_partial, rotation), case,
                                             groups, temperature, on_group)
            status = f"failed in step '{step.name}': {exc}"
            writer.keep_failed(exc, results.make_tree(case, groups, status=status))
            raise
        except Exception as exc:  # a bug: the step fails, what was computed is kept
            err = InternalError.in_step(step.name, exc)
            status = f"failed in step '{step.name}': {err}"
            writer.keep_failed(err, results.make_tree(case, groups, status=status))
            raise err from exc
        groups[step.name] = ds
        if on_group is not None:
            on_group(step.name, ds)
    tree = results.make_tree(case, groups)
    try:
        writer.write_final(tree)
    except KeyboardInterrupt as exc:  # a signal held back while the complete file was written
        exc.partial, exc.output_path = tree, writer.output
        raise
    return tree


def check_case(case: Case):
    """What ``catdae check`` judges before any work: the mesh (with form-found lengths at
    their estimates, which also reject targets an isolated cable cannot reach) and what the
    steps need of it. Returns the mesh; raises CaseError with the field paths."""
    local = formfind.initial_lengths(to_gravity_frame(case)[0])
    mesh = build_mesh(local)
    check_steps(local, mesh)
    return mesh


def _sweep_step(step: Step, case: Case, mesh, absent: set[str], temperature, state: _State,
                progress) -> tuple[xr.Dataset, float | dict]:
    """The step run once per value of its sweep (catdae.case.sweep), each from the same
    starting state, as one dataset with a ``sweep`` dimension. Attributes that differ between
    the values become arrays over them (numbers) or their texts joined by " | ". The state and
    temperature after it are those of the last value. Returns (dataset, temperature)."""
    start = copy.deepcopy(state)
    groups = []
    field = step.sweep.field
    settle = not field.startswith("dampers.")  # a damper moves no equilibrium
    for value in step.sweep.values:
        case_v, step_v = apply_sweep(case, step, value)
        temp_v = temperature if step_v.temperature_change is None else step_v.temperature_change
        run_state = copy.deepcopy(start)
        model = step_model(case_v, mesh.heated(case_v, temp_v), absent, step, run_state)
        groups.append(_run_step(step_v, model, run_state, None, progress, settle=settle))
    state.__dict__.update(run_state.__dict__)
    # the last value's state, under loads or connectors the later steps do not have
    state.unbalanced = settle and field != "temperature_change" and step.kind != "transient"
    ds, varying = join_values(groups)
    ds = ds.assign_coords(sweep=xr.Variable("sweep", np.array(step.sweep.values), {
        "units": sweep_units(field), "long_name": f"swept value of {field}"}))
    return ds.assign_attrs(sweep_field=field, sweep_attributes=" ".join(varying)), temp_v


def step_model(case: Case, mesh, absent: set[str], step: Step, state: _State) -> Model:
    """The model of a step. A transient with ``mass_model = "auto"`` that can snap from the
    state it starts in (catdae.model.snap) gets a mass that carries the axial wave, and its
    ``mass_model_choice`` says why."""
    model = Model(case, mesh, absent, mass_model=step.mass_model, kind=step.kind)
    if step.kind == "transient" and step.mass_model == "auto" and model.mass_model.catenary:
        reason = snap_reason(model, step, state.X, state.V, state.t, state.h)
        if not reason and state.snap and np.any(state.V):  # its wave is still travelling
            reason = f"it continues step '{state.snap}', which took it for a snap"
        if reason:
            model = Model(case, mesh, absent, mass_model="auto", kind=step.kind, snap=reason)
    state.snap = step.name if model.mass_model.snap else ""
    return model


def _run_step(step: Step, model: Model, state: _State, writer, progress,
              settle: bool = False) -> xr.Dataset:
    """One step's dataset. A modal step that changes the scene (``add``, ``remove``,
    ``temperature_change``, or ``settle``: a swept value that moves the equilibrium) first
    finds the static equilibrium of its own scene, and its modes are about that state."""
    if step.kind == "static":
        return _static_step(step, model, state)
    if step.kind == "modal":
        if (settle or step.add or step.remove or step.temperature_change is not None
                or state.unbalanced):
            its = _static_solve(step, model, state)[0].iterations
            return _modal_step(step, model, state).assign_attrs(equilibrium=(
                f"found again for the step's own scene ({its} Newton iterations)"))
        speed = float(np.sqrt((state.V**2).sum(axis=1)).max(initial=0.0))
        if speed > 1e-6:  # after a transient: the state it ended in, moving
            moving = (f"not an equilibrium: the modes linearise the state the previous step "
                      f"ended in, its nodes moving at up to {speed:.3g} m/s; a static step "
                      "before this one gives the modes about equilibrium")
            return _modal_step(step, model, state).assign_attrs(equilibrium=moving,
                                                                note=moving)
        return _modal_step(step, model, state)
    # the only modules that import sksundae; auto's catenary mass run again lumped if it gained
    from catdae.solvers.auto_rerun import run_transient_auto

    ds = as_dataset(run_transient_auto(step, model, state, writer, progress))
    if model.case.seabed is not None:  # touchdown and length on the seabed over time (§17)
        from catdae.model.seabed import SeabedContact
        from catdae.output.seabed import add_seabed_history

        ds = add_seabed_history(ds, model.mesh, model.case.seabed.z,
                                SeabedContact.of_step(model))
    return ds


def _form_step(step: Step, case: Case, removed: set[str], temperature, state: _State):
    """The first static step of a case with form-found cables: the lengths such that their
    targets hold in it (catdae.model.formfind). Returns (case with the lengths, its mesh at the
    reference temperature, the step's model, its dataset)."""

    solves = []

    def evaluate(trial: Case, warm):
        solves.append(trial)
        mesh = build_mesh(trial)
        model = Model(trial, mesh.heated(trial, temperature), removed)
        X, h = (mesh.X0, None) if warm is None else (warm[2].X, warm[2].state.h)
        sol = solve_static(model, X, h, t=state.t, load_steps=step.load_steps)
        return (mesh, model, sol), formfind.summary_of(trial, model, sol)

    found, (mesh, model, sol) = formfind.solve(case, evaluate)
    return found, mesh, model, _static_result(model, state, sol).assign_attrs(
        form_static_solves=len(solves))  # the search's cost: a static solve of the scene each


def _static_solve(step: Step, model: Model, state: _State):
    """The static equilibrium of the step's scene from the current state, which it becomes
    (at rest). Returns (solution, the model whose tensions it holds, the seabed summary or
    None)."""
    summary = None
    try:
        if model.case.seabed is not None:  # docs/theory.md §17
            from catdae.solvers.seabed_static import solve_static_on_seabed

            sol, model, summary = solve_static_on_seabed(model, state.X, state.h, t=state.t,
                                                         load_steps=step.load_steps)
        else:
            sol = solve_static(model, state.X, state.h, t=state.t, load_steps=step.load_steps)
    except ConvergenceError as exc:  # a likely cause in the case, if there is one
        hint = plausibility_note(model.case, waves=False) if model.fluid is not None else ""
        if not hint:
            raise
        raise ConvergenceError(f"{exc} ({hint})") from exc
    state.X, state.h, state.unbalanced = sol.X, sol.state.h, False
    state.V = np.zeros_like(sol.X)
    return sol, model, summary


def _static_step(step: Step, model: Model, state: _State) -> xr.Dataset:
    sol, model, summary = _static_solve(step, model, state)
    ds = _static_result(model, state, sol)
    if summary is None:
        return ds
    from catdae.output.seabed import add_seabed, static_seabed_note

    ds = add_seabed(ds, model.mesh, summary)
    if model.case.seabed.stiffness is None:
        return ds
    # contact springs at the nodes (§17.5); no friction in statics
    return results.with_note(ds, static_seabed_note(ds, model.mesh, model.case.seabed))


def _static_result(model: Model, state: _State, sol) -> xr.Dataset:
    state.X, state.h, state.unbalanced = sol.X, sol.state.h, False
    state.V = np.zeros_like(sol.X)
    ds = results.static_dataset(
        model.mesh, sol.X, model.tensions(sol.state), model.reactions(sol.state, state.t, sol.X),
        {"iterations": sol.iterations, "residual_norm": sol.residual_norm,
         "load_increments": sol.load_steps, "status": "completed"},
        cables=model.cable_summary(sol.X, sol.state),
    )
    ds = with_connector_forces(ds, model.connectors, sol.X)
    ds = with_static_fluid(ds, model.fluid, sol.X, state.t)  # the current, the wind (§13)
    if model.fluid is not None:
        ds = results.with_note(ds, plausibility_note(model.case, waves=False))
    return engineering.add_static(ds, span_quantities(model, sol.X, sol.state), model.case)


def _partial(step: Step, ds: xr.Dataset, case: Case, groups, temperature, on_group):
    """What a failed or interrupted step computed, with the engineering results of its outputs
    so far (envelopes, jump, swing), shown as a finished step is (``on_group``)."""
    with suppress(Exception):  # the partial results are kept whatever happens here
        ds = engineering_results(step, ds, case, groups, temperature)
    if on_group is not None and step.kind == "transient":
        with suppress(Exception):
            on_group(step.name, ds)
    return ds


def engineering_results(step: Step, ds: xr.Dataset, case: Case,
                        groups: dict[str, xr.Dataset], temperature) -> xr.Dataset:
    """A step's group (in the case's axes) with, for a temperature change uniform over the
    cables, the attrs ``temperature_change`` (K) and, with the case's
    ``reference_temperature``, ``temperature``; in a case with a thermal field, a static or
    transient group also has them per cable; a transient group also with its envelopes and,
    after a ``jump_reference`` static step, the jump of each cable
    (catdae.output.engineering)."""
    if step.sweep is not None and step.sweep.field == "temperature_change":
        temperature = np.array(step.sweep.values)  # one per value (the sweep's attributes)
        ds.attrs["sweep_attributes"] = " ".join(sorted(
            {*ds.attrs["sweep_attributes"].split(), "temperature_change", "temperature"}))
    names = [c.name for c in case.cables]
    per = engineering.cable_temperature_changes(names, temperature)
    if isinstance(temperature, Mapping) and names and np.all(per == per[0]):
        temperature = float(per[0])  # a table that gives every cable the same change
    if not isinstance(temperature, Mapping):
        ds = ds.assign_attrs(temperature_change=_number(temperature))
        if case.reference_temperature is not None:
            ds = ds.assign_attrs(temperature=_number(case.reference_temperature + temperature))
    if step.kind == "transient":
        ref = groups.get(step.jump_reference) if step.jump_reference else None
        ds = ds.assign_attrs(jump_reference=step.jump_reference) if ref is not None else ds
        start = engineering.start_tension(step, groups)
        ds = per_value(ds, lambda d: engineering.add_transient(
            d, case, ref, -np.asarray(case.gravity_direction, float), start=start))
    if step.kind != "modal" and names and _thermal(case):
        ds = engineering.add_temperatures(ds, names, temperature, case.reference_temperature)
    return effective_tension(ds, case.water is not None)


def _thermal(case: Case) -> bool:
    """Whether a case has a thermal field: a reference temperature, a step's temperature (or
    change), a temperature sweep."""
    return case.reference_temperature is not None or any(
        s.temperature_change is not None
        or (s.sweep is not None and s.sweep.field == "temperature_change") for s in case.steps)


def _number(x):  # a float, or an array of them over the values of a sweep
    return x.astype(float) if isinstance(x, np.ndarray) else float(x)


def _modal_step(step: Step, model: Model, state: _State) -> xr.Dataset:
    model.set_time(state.t)
    if model.case.seabed is not None:  # the seabed's contact springs (docs/theory.md §17)
        from catdae.model.seabed import ContactModel

        model = ContactModel.of(model)
    est = model.element_state(state.X, state.h)
    if (est.status == NOT_CONVERGED).any():
        raise ConvergenceError(f"modal step '{step.name}': an element cannot be solved in the "
                               "current configuration")
    sol = solve_modal(model, state.X, est, step.modes)
    ds = results.modal_dataset(model.mesh, sol.frequency, sol.shape, sol.plane, sol.symmetry,
                               {"solver": sol.solver, "mass_model": model.mass_model.name,
                                "mass_model_setting": model.mass_model.setting,
                                "mass_model_choice": model.mass_model.choice,
                                "status": "completed", "modes_requested": step.modes})
    damped = solve_damped(model, state.X, est, step.modes, step.damping)
    if damped is not None:  # docs/theory.md §16
        modes, shapes = damped
        plane, symmetry = classify(model, state.X, shapes.real)
        ds = with_damped_modes(ds, modes, shapes, plane, symmetry).assign_attrs(
            damped_solver=modes.solver)
    return ds
