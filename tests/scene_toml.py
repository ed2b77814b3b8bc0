"""TOML text of the one-cable scene that many tests run: cable ``c`` from node A to node B.

``cable_scene`` writes, in this order and without blank lines::

    title, gravity                       (each only when given)
    [materials.<material>]  EA, mass, weight (weight only when given)
    [nodes]                 A, B
    [supports]              one ``<name> = "pinned"`` line per entry of ``supports``
    [[cables]]              name, ends = ["A", "B"], material, length, elements, gauss_points
    extra                   verbatim (loads, point masses, support motions, ...)
    steps                   verbatim

Numbers are written with ``num`` (by default ``repr(float(x))``: a TOML float, also for numpy
scalars; a number given as a string, e.g. ``"4.696e8"``, is written as it stands).
``elements`` and ``gauss_points`` are written as integers and left out when ``None``. ``extra``
and ``steps`` get a closing newline if they lack one. A string in ``supports`` that already
holds ``=`` (e.g. ``'B = ["y", "z"]'``) is written as it stands.

``static_step``, ``modal_step`` and ``transient_step`` give the ``[[steps]]`` blocks most scenes
end with.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence


def _float(x) -> str:
    """A TOML float (also for numpy scalars); a string is taken as already written."""
    return x if isinstance(x, str) else repr(float(x))


def _block(text: str) -> str:
    return text if not text or text.endswith("\n") else text + "\n"


def cable_scene(*, B, L0, EA, mass, elements: int | None = None, A=(0.0, 0.0, 0.0),
                weight=None, gauss_points: int | None = None,
                supports: Sequence[str] = ("A", "B"), title: str | None = None, gravity=None,
                material: str = "m", cable: str = "c", extra: str = "", steps: str = "",
                num: Callable[[object], str] = _float) -> str:
    """One cable from node A to node B, as TOML text (see the module docstring for the layout)."""
    lines = []
    if title is not None:
        lines.append(f'title = "{title}"')
    if gravity is not None:
        lines.append(f"gravity = {num(gravity)}")
    lines += [f"[materials.{material}]", f"EA = {num(EA)}", f"mass = {num(mass)}"]
    if weight is not None:
        lines.append(f"weight = {num(weight)}")
    lines += ["[nodes]",
              "A = [" + ", ".join(num(a) for a in A) + "]",
              "B = [" + ", ".join(num(b) for b in B) + "]",
              "[supports]"]
    lines += [s if "=" in s else f'{s} = "pinned"' for s in supports]
    lines += ["[[cables]]", f'name = "{cable}"', 'ends = ["A", "B"]',
              f'material = "{material}"', f"length = {num(L0)}"]
    if elements is not None:
        lines.append(f"elements = {elements}")
    if gauss_points is not None:
        lines.append(f"gauss_points = {gauss_points}")
    return "\n" + "".join(line + "\n" for line in lines) + _block(extra) + _block(steps)


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
            f"rtol = {num(rtol)}\natol = {num(atol)}\n" + _block(extra))
