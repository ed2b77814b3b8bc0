"""Side by side with MoorDyn (PyPI ``moordyn``, RK4) on issue 25's scenes: the pendulum and the
violent example 2 at 50 segments. Cost of MoorDyn's own integration (the CPU inside its Step
calls, and its initial-condition solve separately), the quantity compared, and MoorDyn's
internal time step. The catdae side is benchmarks/ringing.py; the table is in ringing.md.

MoorDyn writes a progress line per Step to the C stdout: it is sent to /dev/null here.
``python benchmarks/moordyn_compare.py [pendulum] [violent] [--segments N]``
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import tempfile
import time

import moordyn

G = 9.81


@contextlib.contextmanager
def quiet_stdout():
    """The C library's stdout (fd 1) to /dev/null."""
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(null)
        os.close(saved)


def _input(title, line_type, points, line, dt_opt, ic="") -> str:
    return f"""--------------------- MoorDyn Input File ------------------------------------
{title}
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI   Cd   Ca   CdAx  CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2) (-) (-) (-)  (-)
{line_type}
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
{points}
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
{line}
---------------------- OPTIONS -----------------------------------------
0             writeLog      -
{dt_opt}
RK4           tScheme       -
{ic}------------------------- need this line --------------------------------------
"""


def _run(text, fn):
    folder = tempfile.mkdtemp()
    path = os.path.join(folder, "case.txt")
    with open(path, "w") as f:
        f.write(text)
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with quiet_stdout():
            return fn(path)
    finally:
        os.chdir(cwd)


def pendulum(segments=10, zeta=0.01, cfl=0.1, periods=5.0) -> dict:
    """MoorDyn's own pendulum test (tests/Mooring/pendulum.txt, its internal damping 1 % of
    critical per segment) with ``segments`` segments: period (all zero crossings) and amplitude
    of the mass over the ``periods``-th period (periods - 0.5 to periods + 0.25 reference
    periods; the run ends at periods + 0.3)."""
    text = _input(
        "pendulum", f"main 0.1 7.85398 1.0E9 {-zeta} 0 0.0 0.0 0.0 0.0",
        "1 Fixed 0 0 0 0 0 0 0\n2 Free 10 0 -100 1E5 0 0 0",
        f"1 main 1 2 100.5 {segments} -", f"{cfl} cfl -",
        "1000.0 WtrDnsty -\n500 WtrDpth -\n")

    def go(path):
        c0 = time.process_time()
        s = moordyn.Create(path)
        moordyn.SetVerbosity(s, moordyn.LEVEL_ERR)
        pt = moordyn.GetPoint(s, 2)
        x0 = moordyn.GetPointPos(pt)
        moordyn.Init(s, [], [])
        c_init = time.process_time() - c0
        length = math.hypot(x0[0], x0[2])
        th0 = math.asin(x0[0] / length)
        ref = 2 * math.pi * math.sqrt(length / G) * (1 + th0**2 / 16)
        dt = 0.05
        t, xs, ts = 0.0, [x0[0]], [0.0]
        c1 = time.process_time()
        while t < periods * ref + 0.3 * ref:
            moordyn.Step(s, [], [], t, dt)
            t += dt
            xs.append(moordyn.GetPointPos(pt)[0])
            ts.append(t)
        c_steps = time.process_time() - c1
        dtm = moordyn.GetDt(s) if hasattr(moordyn, "GetDt") else float("nan")
        moordyn.Close(s)
        cross = [ts[k] - xs[k] * dt / (xs[k + 1] - xs[k]) for k in range(len(xs) - 1)
                 if (xs[k] > 0) != (xs[k + 1] > 0)]
        period = 2 * (cross[-1] - cross[0]) / (len(cross) - 1)
        amp = max(abs(x) for x, tt in zip(xs, ts, strict=True)
                  if (periods - 0.5) * ref < tt <= (periods + 0.25) * ref)
        return {"period_err": period / ref - 1, "amp_err": amp / x0[0] - 1, "cpu_steps": c_steps,
                "cpu_init": c_init, "dtM": dtm}

    return _run(text, go)


def _end_a(t, w):
    """End A's position and velocity at t: y = 3 (1 - cos wt), z = 3 sin wt."""
    return ([0.0, 3 * (1 - math.cos(w * t)), 3 * math.sin(w * t)],
            [0.0, 3 * w * math.sin(w * t), 3 * w * math.cos(w * t)])


def violent(segments=50, duration=4.0, cfl=0.5, dt_c=1e-4, exact=False) -> dict:
    """The violent example 2 (span 10 m, 15 m of wire, EA 3.4e7, 5 kg/m, in air: water
    density 1e-9), end A coupled and moved as a = 3 m: y = a (1 - cos πt), z = a sin πt. The
    peak of MoorDyn's largest node tension (GetLineMaxTen), read after every coupling step ``dt_c``.

    MoorDyn takes a coupled point's position at the start of the step and moves it on from there
    at the velocity it is given (Point::updateFairlead: r = x + v τ, 0 <= τ <= dt_c); by default
    the driver hands it the end-of-step position and velocity, so the point leads by one coupling
    step (its first step jumps 3π dt_c m). ``exact``: the start-of-step position and the chord
    velocity to the next one, so that the point passes through every exact position; and the peak
    read over nodes 0..N: GetLineMaxTen stops at node N - 1 (the average of the two last segments'
    tensions), GetLineFairTen is node N, the last segment at end B, where the peak is."""
    text = _input(
        "violent example 2", "wire 0.0113 5.0 3.4E7 0.0 0 0.0 0.0 0.0 0.0",
        "1 Coupled 0 0 0 0 0 0 0\n2 Fixed 10 0 0 0 0 0 0",
        f"1 wire 1 2 15.0 {segments} -", f"{cfl} cfl -",
        "1e-9 WtrDnsty -\n200 WtrDpth -\n0.5 dtIC -\n100.0 TmaxIC -\n1e-5 threshIC -\n")

    def go(path):
        c0 = time.process_time()
        s = moordyn.Create(path)
        moordyn.SetVerbosity(s, moordyn.LEVEL_ERR)
        moordyn.Init(s, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        line = moordyn.GetLine(s, 1)
        c_init = time.process_time() - c0
        peak, t_peak, c_steps = 0.0, 0.0, 0.0
        w = math.pi
        for k in range(int(round(duration / dt_c))):
            te = (k + 1) * dt_c
            x, v = _end_a(te, w)
            if exact:
                x0 = _end_a(k * dt_c, w)[0]
                x, v = x0, [(b - a) / dt_c for a, b in zip(x0, x, strict=True)]
            c1 = time.process_time()
            moordyn.Step(s, x, v, k * dt_c, dt_c)
            c_steps += time.process_time() - c1
            tension = moordyn.GetLineMaxTen(line)
            if exact:
                tension = max(tension, moordyn.GetLineFairTen(line))
            if tension > peak:
                peak, t_peak = tension, te
        moordyn.Close(s)
        return {"peak": peak, "t_peak": t_peak, "cpu_steps": c_steps, "cpu_init": c_init}

    return _run(text, go)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=["pendulum", "violent"])
    ap.add_argument("--duration", type=float, default=4.0)
    args = ap.parse_args()
    print(f"moordyn {getattr(moordyn, '__version__', '?')}, load {os.getloadavg()[0]:.2f}")
    if "pendulum" in args.scenes:
        for seg, zeta in ((10, 0.01), (10, 0.0), (20, 0.01)):
            r = pendulum(seg, zeta)
            print(f"| MoorDyn pendulum, {seg} segments, BA/-zeta {-zeta:g} | "
                  f"{r['cpu_steps']:.2f} s (+ {r['cpu_init']:.2f} s init) | period "
                  f"{100 * r['period_err']:+.3f} % | amplitude {100 * r['amp_err']:+.3f} % |",
                  flush=True)
    if "violent" in args.scenes:
        for cfl, dt_c in ((0.5, 1e-4), (0.25, 2e-5)):
            r = violent(50, args.duration, cfl, dt_c)
            print(f"| MoorDyn violent, 50 segments, cfl {cfl:g}, coupling {dt_c:g} s | "
                  f"{r['cpu_steps']:.2f} s (+ {r['cpu_init']:.2f} s init) | peak "
                  f"{r['peak'] / 1e3:.1f} kN at {1e3 * r['t_peak']:.2f} ms |", flush=True)


if __name__ == "__main__":
    main()
