"""TOML text of the test scenes: one builder for every scene a test writes (and the shared
scenes themselves, e.g. ``long_transient``). Most are the one-cable scene, cable ``c`` from node
A to node B.

``cable_scene`` writes, in this order and without blank lines::

    title, gravity, head    (each only when given; ``head``: further top-level keys)
    [materials.<material>]  EA, mass, weight, properties (weight only when given;
                            ``properties``: further fields of the material, e.g. diameter)
    [nodes]                 A, B, nodes (``nodes``: further nodes, e.g. a ground node)
    [supports]              one ``<name> = "pinned"`` line per entry of ``supports``
    [[cables]]              name, ends = ["A", "B"], material, length, elements, gauss_points
    extra                   verbatim (loads, point masses, support motions, ...)
    steps                   verbatim

The numbers of the nodes, EA, mass, weight, length and gravity are written with ``num`` (by
default ``repr(float(x))``: a TOML float, also for numpy scalars; a number given as a string,
e.g. ``"4.696e8"``, is written as it stands; a sequence, e.g. a gravity vector, as an array of
such numbers). ``elements`` and ``gauss_points`` are written as integers and left out when
``None``; ``head`` and ``properties`` values as ``value`` writes them (below). ``extra`` and
``steps`` get a closing newline if they lack one. A string in ``supports`` that already holds
``=`` (e.g. ``'B = ["y", "z"]'``) is written as it stands.

``static_step``, ``modal_step`` and ``transient_step`` give the ``[[steps]]`` blocks most scenes
end with.

Scenes of several cables, or with other node names, are written by ``scene`` in the same layout
(``head`` keys, ``[materials.*]``, ``[nodes]``, ``[supports]``, then the ``[[cables]]`` blocks,
``extra`` and ``steps``); ``cable_scene`` is ``scene`` with one cable from A to B. The blocks of
the arrays of tables are written by ``table`` (one ``key = value`` line per field given, in the
order given, ``None`` left out) and its named forms ``cable``, ``point_mass``, ``load``,
``distributed_load``, ``support_motion``, ``spring``, ``damper``, ``bar`` and ``step``; a plain
table (``[seabed]``, ``[ground]``, ...) by ``section``; lines written verbatim (with a closing
newline) by ``block``. Values (``value``): a bool as
``true``/``false``, an integer as such, any other number as ``num`` writes it, a string quoted
(``raw(...)`` as it stands), a sequence as an array and a mapping as an inline table.

Shared scenes: ``long_transient`` (a transient that is always interrupted before its end) and
``falling_mass`` (a mass dropped onto a slack rope: the snap).
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Mapping, Sequence


def _float(x) -> str:
    """A TOML float (also for numpy scalars); a string is taken as already written."""
    return x if isinstance(x, str) else repr(float(x))


def block(text: str) -> str:
    """Lines written verbatim, with a closing newline when there are any."""
    return text if not text or text.endswith("\n") else text + "\n"


class raw(str):  # noqa: N801 (used like a function: raw("4.696e8"))
    """A value written into the TOML as it stands (a number already written, an expression)."""


def value(v, num: Callable[[object], str] = _float) -> str:
    """``v`` as a TOML value (see the module docstring)."""
    if isinstance(v, raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        return num(v)
    if isinstance(v, str):
        return '"' + v + '"'
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{k} = {value(x, num)}" for k, x in v.items()) + " }"
    return "[" + ", ".join(value(x, num) for x in v) + "]"


def _lines(fields: Mapping, num: Callable[[object], str] = _float) -> list[str]:
    return [f"{k} = {value(v, num)}" for k, v in fields.items() if v is not None]


def table(array: str, /, **fields) -> str:
    """One ``[[array]]`` block: a ``key = value`` line per field that is not ``None``."""
    return "".join(line + "\n" for line in [f"[[{array}]]", *_lines(fields)])


def section(name: str, /, **fields) -> str:
    """One ``[name]`` table: a ``key = value`` line per field that is not ``None``."""
    return "".join(line + "\n" for line in [f"[{name}]", *_lines(fields)])


def cable(name: str, ends=("A", "B"), material: str = "m", length=None, elements=None,
          **more) -> str:
    """A ``[[cables]]`` block (``more``: gauss_points, form, ... in the order given)."""
    return table("cables", name=name, ends=list(ends), material=material, length=length,
                 elements=elements, **more)


_cable = cable  # for cable_scene, whose argument ``cable`` is the cable's name


def point_mass(name: str, mass, *, node=None, cable=None, s=None, **more) -> str:
    """A ``[[point_masses]]`` block: at a node, or at arc length ``s`` along a cable."""
    return table("point_masses", name=name, node=node, cable=cable, s=s, mass=mass, **more)


def load(name: str, force, *, node=None, cable=None, s=None, **more) -> str:
    """A ``[[loads]]`` block: a force at a node, or at arc length ``s`` along a cable (``more``:
    time, active, ...)."""
    return table("loads", name=name, node=node, cable=cable, s=s, force=force, **more)


def distributed_load(cable: str, load, **more) -> str:
    """A ``[[distributed_loads]]`` block."""
    return table("distributed_loads", cable=cable, load=load, **more)


def support_motion(node: str, **axes) -> str:
    """A ``[[support_motions]]`` block: ``axes`` maps x, y, z to time functions (mappings)."""
    return table("support_motions", node=node, **axes)


def spring(name: str, ends, stiffness, **more) -> str:
    """A ``[[springs]]`` block (``more``: length, ...)."""
    return table("springs", name=name, ends=list(ends), stiffness=stiffness, **more)


def damper(name: str, ends, coefficient, **more) -> str:
    """A ``[[dampers]]`` block."""
    return table("dampers", name=name, ends=list(ends), coefficient=coefficient, **more)


def bar(name: str, ends, EA, **more) -> str:
    """A ``[[bars]]`` block (``more``: mass, length, ...)."""
    return table("bars", name=name, ends=list(ends), EA=EA, **more)


def step(kind: str, /, name: str | None = None, **fields) -> str:
    """A ``[[steps]]`` block of any kind (``name`` left out when ``None``)."""
    return table("steps", kind=kind, name=name, **fields)


def scene(*, nodes: Mapping[str, Sequence], cables: str | Sequence[str],
          materials: Mapping[str, Mapping], supports: Sequence[str] = ("A", "B"),
          head: Mapping | None = None, extra: str = "", steps: str = "",
          num: Callable[[object], str] = _float) -> str:
    """A scene of any cables, as TOML text (see the module docstring for the layout).

    ``head``: the top-level keys (title, gravity, source, ...); ``materials``: name -> fields;
    ``supports``: node names (pinned) or whole lines; ``cables``: ``cable(...)`` blocks."""
    lines = _lines(head or {}, num)
    for name, fields in materials.items():
        lines += [f"[materials.{name}]", *_lines(fields, num)]
    lines += ["[nodes]", *(f"{n} = {value(list(x), num)}" for n, x in nodes.items()),
              "[supports]"]
    lines += [s if "=" in s else f'{s} = "pinned"' for s in supports]
    blocks = cables if isinstance(cables, str) else "".join(cables)
    return "\n" + "".join(line + "\n" for line in lines) + blocks + block(extra) + block(steps)


def cable_scene(*, B, L0, EA, mass, elements: int | None = None, A=(0.0, 0.0, 0.0),
                weight=None, gauss_points: int | None = None,
                supports: Sequence[str] = ("A", "B"), title: str | None = None, gravity=None,
                head: Mapping | None = None, properties: Mapping | None = None,
                nodes: Mapping[str, Sequence] | None = None,
                material: str = "m", cable: str = "c", extra: str = "", steps: str = "",
                num: Callable[[object], str] = _float) -> str:
    """One cable from node A to node B, as TOML text (see the module docstring for the layout)."""
    def n(x):
        if x is None or isinstance(x, raw):
            return x
        if isinstance(x, str | numbers.Real):
            return raw(num(x))
        return [n(v) for v in x]

    return scene(head={"title": title, "gravity": n(gravity), **(head or {})},
                 materials={material: {"EA": n(EA), "mass": n(mass), "weight": n(weight),
                                       **(properties or {})}},
                 nodes={"A": n(A), "B": n(B), **{k: n(x) for k, x in (nodes or {}).items()}},
                 supports=supports,
                 cables=_cable(cable, ("A", "B"), material, n(L0), elements,
                               gauss_points=gauss_points),
                 extra=extra, steps=steps, num=num)


def static_step(name: str = "st") -> str:
    """A ``[[steps]]`` block: static equilibrium named ``name``."""
    return f'[[steps]]\nkind = "static"\nname = "{name}"\n'


def modal_step(modes: int, name: str = "modes", mass_model: str | None = None) -> str:
    """A ``[[steps]]`` block: ``modes`` natural modes named ``name`` (optionally a mass model)."""
    mm = "" if mass_model is None else f'mass_model = "{mass_model}"\n'
    return f'[[steps]]\nkind = "modal"\nname = "{name}"\nmodes = {modes}\n{mm}'


def transient_step(name: str, duration, output_interval, *, rtol, atol, remove=None,
                   extra: str = "", num: Callable[[object], str] = _float) -> str:
    """A ``[[steps]]`` block: a transient named ``name``; ``remove`` (load names) is written only
    when given, ``extra`` (further keys of the step, e.g. ``damping = ...``) verbatim at its end."""
    rm = "" if remove is None else "remove = [" + ", ".join(f'"{r}"' for r in remove) + "]\n"
    return (f'[[steps]]\nkind = "transient"\nname = "{name}"\n{rm}'
            f"duration = {num(duration)}\noutput_interval = {num(output_interval)}\n"
            f"rtol = {num(rtol)}\natol = {num(atol)}\n" + block(extra))


def long_transient(duration=1000.0) -> str:
    """A weightless taut cable (chord 10 m, 10 % strain, 2 elements) pushed sideways at c.1 by
    1 N (load "push") in the static step "static", then released for ``duration`` seconds in the
    transient "dyn" (about 200 s of wall time per 1000 s simulated: a run of it is always
    interrupted long before its end)."""
    return cable_scene(
        B=(10.0, 0.0, 0.0), L0=10.0 / 1.1, EA=1e4, mass=2.0, weight=0.0, elements=2,
        extra=load("push", [0.0, 1.0, 0.0], node="c.1"),
        steps=static_step("static") + transient_step("dyn", duration, 0.01, rtol=1e-6,
                                                     atol=1e-9, remove=["push"]))


def falling_mass(rope_mass, *, duration, M=1000.0, L0=10.0, EA=1e7, x_off=0.3, fall=0.5,
                 output_interval=0.05) -> str:
    """A mass M (point mass "bob" at B) on a slack rope of one element (``rope_mass`` per metre,
    material "rope"), released from rest ``fall`` m below the taut length with B ``x_off`` m
    aside (so that the slack rope has a shape); no weight given: the default gravity. One
    lumped-mass transient "drop" of ``duration`` seconds: the snap as the rope catches it."""
    return cable_scene(
        B=(x_off, 0.0, -(L0 - fall)), L0=L0, EA=EA, mass=rope_mass, elements=1,
        supports=("A",), material="rope",
        extra=point_mass("bob", M, node="B"),
        steps=step("transient", "drop", mass_model="lumped", duration=duration,
                   output_interval=output_interval))
