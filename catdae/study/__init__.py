"""Accuracy and cost studies: work-precision sweeps, on this machine or on a Dask cluster.

:func:`run_study` runs one step of a case, the *study step*, over the cartesian product of solver
and mesh settings, measures what each run cost and how far it is from a reference run, and
returns one labelled ``xarray.Dataset`` whose dimensions are the settings. ``catdae study`` is
the same from the command line, with netCDF output and work-precision plots (PNG).

The pipeline, in order:

1. grid: each setting is a list (default: the case's own value); a run is one combination.
   Transient steps sweep ``rtol``, ``atol``, ``elements``, ``gauss_points``, ``mass_model``,
   ``linear_solver`` and ``max_order``; modal steps the last-but-three mesh and mass settings.
2. configure: one ``Case`` per run (the study step and the steps before it; later steps are
   dropped). ``elements`` and ``gauss_points`` apply to every cable, the solver settings to the
   study step only. The run's key is a hash of that configured case.
3. execute: every run not already in the store is an independent task (:func:`execute`, a
   picklable Case in, a small Dataset out). By default the tasks run on a
   ``distributed.LocalCluster`` of 2 single-threaded worker processes bound to 127.0.0.1 (a
   script that starts one needs the ``if __name__ == "__main__":`` guard, as for any
   multiprocessing); a scheduler address or a ``distributed.Client`` sends the same tasks to an
   existing cluster; ``"synchronous"`` runs them here, one after the other, and lets any
   unexpected exception through (for debugging).
4. store: the client writes each finished run to ``<store>/<key>.nc`` as it arrives, so a study
   that crashed or lost a worker resumes where it stopped: a rerun skips stored runs.
5. errors, against the reference, in the client; then the Dataset.

Reference. Unless one is given, the reference is one more run, made more accurate than every
run in what the study varies: ``rtol`` and ``atol`` are 1/100 of the smallest swept values;
when ``elements`` is swept (more than one value) it is ``2 * max(elements)``, otherwise the
runs' own mesh, so that a tolerance sweep measures the time-integration error alone, not the
spatial error of the mesh; a swept ``gauss_points`` becomes ``max + 1`` (at most 10), a swept
``mass_model`` "auto", a swept ``max_order`` 5, a swept ``linear_solver`` "auto". A
mapping ``reference={"elements": 128}`` overrides any of these; a Dataset (the study step's
group of a catdae results file) is used as it is. The settings used are in the output attrs.

Response and error. Meshes differ between runs, so a transient error is measured at a point
that is a node of every mesh: a named node of the case (not a fully fixed support), or the mesh
node at unstrained arc-length fraction k/n from the first end of a cable, which exists in a mesh
of n' elements when k n'/n is an integer. Such points are labelled ``<cable>@<fraction>``
(``main@1/2`` is the midspan node: ``main.7`` of 14 elements, ``main.4`` of 8). The default
response is the common point that moves most in the reference; a grid whose meshes share no
point is rejected before anything runs (choose element counts with a common factor: with all
counts even, the midspan node is shared). ``response`` may name a case node, ``<cable>@<p/q>``,
or ``<cable>.<k>`` meaning node k of the case file's own mesh (fraction k/elements). The error is
the largest distance over the reference's output times between the run's displacement there
(interpolated linearly in time) and the reference's, in m. For a modal step it is the largest
relative error of the lowest natural frequencies (``response``: how many; default the step's
``modes``), with the signed errors per mode in ``frequency_error``: each reference mode is
paired with the run's mode of the same shape (``catdae.study.modes``; ``matched_mode``,
``shape_correlation``), and one the run does not resolve makes its error inf.
A modal ``response`` ``"frequency:<k>"`` takes mode k's error alone; a static study step
(settings ``elements``, ``gauss_points``) measures the relative error of one static quantity
of a cable, ``"<quantity>:<cable>"`` (``catdae.study.quantity``).

Costs. ``wall_time`` is the time of the study step alone, from the end of the step before it to
the end of its results (the static steps before it are not counted), in a worker that has
already run the same kind of step once (the first, untimed, warm-up run of a process loads the
compiled kernels). ``n_steps``, ``n_residual_evaluations`` and ``n_jacobian_evaluations`` are the
transient step's own attrs. ``peak_memory`` is, by default (``memory="rss"``), how much the
worker process's resident set grew during the run: on Linux exactly, by resetting the process's
peak (VmHWM, through /proc/self/clear_refs) before the run and reading it after; elsewhere the
growth of ``getrusage``'s lifetime peak ``ru_maxrss``, which reads 0 when an earlier run in the
same process went higher. It counts everything (numpy, SUNDIALS, numba) at no cost, one run per
process at a time (threads_per_worker=1). ``memory="tracemalloc"`` records the peak of Python
and numpy allocations only, and makes the runs about 3-4 times slower, their wall time too. The
method used is in the variable's long_name and the attr ``peak_memory_method``.

Modules: ``core`` (settings, grid, configured runs and their keys, response points), ``worker``
(:func:`execute`, the task, and the memory probe), ``runner`` (:func:`run_study` and the Dask
execution), ``store`` (the resumable store), ``dataset`` (errors and the Dataset), ``plots``
(orders and plots), ``report`` (:func:`write_study`, :func:`summary`), ``cli`` (:func:`main`).
"""

from __future__ import annotations

# ``name as name``: public as before, though not in __all__
from catdae.study.cli import main
from catdae.study.core import MODAL_SETTINGS as MODAL_SETTINGS
from catdae.study.core import SETTINGS, StudyError
from catdae.study.core import STORE_FORMAT as STORE_FORMAT
from catdae.study.core import configure as configure
from catdae.study.core import point_labels as point_labels
from catdae.study.core import reference_settings as reference_settings
from catdae.study.core import run_key as run_key
from catdae.study.core import settings_grid as settings_grid
from catdae.study.core import study_step as study_step
from catdae.study.plots import convergence_order, plot_convergence, plot_work_precision
from catdae.study.report import summary as summary
from catdae.study.report import write_study
from catdae.study.runner import local_cluster as local_cluster
from catdae.study.runner import run_study
from catdae.study.worker import execute

__all__ = ["SETTINGS", "StudyError", "convergence_order", "execute", "main", "plot_convergence",
           "plot_work_precision", "run_study", "write_study"]
