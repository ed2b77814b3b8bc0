"""The benchmarks' 100 m cable as TOML text (transient_speed.py and speed_accuracy.py, and through
them opensees_compare.py, scaling_issue11.py, ...): span 100 m level, L0 = 102 m, EA = 1e8 N,
weight 100 N/m, mass 100/9.81 kg/m, pinned ends, ``gauss_points = 3``; one support moves as
``offset - offset cos(π t)`` along one axis; a static step "initial", then a transient "motion"."""

from __future__ import annotations

MASS = 100.0 / 9.81  # kg/m: weight 100 N/m at g = 9.81


def hundred_metre_cable(*, title: str, elements: int, node: str, axis: str, amplitude: float,
                        duration: float, output_interval: float, rtol: float, atol: float,
                        mass_model: str | None = None) -> str:
    """The cable with ``node`` moving along ``axis`` as amplitude (1 - cos π t); ``mass_model``
    is written into the transient step only when given."""
    mm = "" if mass_model is None else f'mass_model = "{mass_model}"\n'
    return f"""
title = "{title}"
gravity = 9.81

[materials.m]
EA = 1.0e8
mass = {MASS!r}
weight = 100.0

[nodes]
A = [0.0, 0.0, 0.0]
B = [100.0, 0.0, 0.0]

[supports]
A = "pinned"
B = "pinned"

[[cables]]
name = "c"
ends = ["A", "B"]
material = "m"
length = 102.0
elements = {elements}
gauss_points = 3

[[support_motions]]
node = "{node}"
{axis} = {{ kind = "cosine", amplitude = {-amplitude!r}, frequency = 0.5, offset = {amplitude!r} }}

[[steps]]
kind = "static"
name = "initial"

[[steps]]
kind = "transient"
name = "motion"
duration = {duration!r}
output_interval = {output_interval!r}
rtol = {rtol!r}
atol = {atol!r}
{mm}"""


def opensees_job(st, ne: int, motion=None, **more) -> dict:
    """The OpenSees model (opensees_compare.py's worker) of the ne-element cable, its nodes at
    catdae's static equilibrium ``st`` (the dataset of the step "initial"); ``motion``: (node
    name, axis index, amplitude) of the moving support when not the worker's default; ``more``:
    error_tol, duration, ... added as given."""
    order = {str(n): k for k, n in enumerate(st.node.values)}
    if motion is not None:
        more["motion"] = [order[motion[0]], *motion[1:]]
    chain = ["A"] + [f"c.{k}" for k in range(1, ne)] + ["B"]
    conn = [[order[chain[k]], order[chain[k + 1]]] for k in range(ne)]
    return {"X": st.position.values.tolist(), "conn": conn,
            "supports": [order["A"], order["B"]], "mid": order[f"c.{ne // 2}"],
            "EA": 1.0e8, "weight": -100.0, "rho": MASS, "L0e": [102.0 / ne] * ne,
            "newton_tol": 1e-10, "ne": ne, **more}
