"""The cost of the groups solved by Newton's method, fused residual and Jacobian against the
pair-by-pair path (issue 24 item 2), written to ``benchmarks/results_newton.md``.

Run: ``python benchmarks/bench_newton.py`` (about 2 min; ``--quick``: fewer rounds, no
``linkage enumerate``; ``--enumerate``: also time ``linkage enumerate six_bar --newton`` once each
way, several minutes more).

Contenders: the fused path (:mod:`assur.fused`, ``assur.fused.FUSED = True``: one array expression
per kind of pair for the whole residual and Jacobian) and the pair-by-pair path
(``FUSED = False``: :meth:`assur.base.Group.residual` / :meth:`assur.base.Group.jacobians` and
:func:`assur.generic.newton_pairwise`, the code as it was). Groups: the class-III triad of
``six_bar_class3`` and the group of ``cylinder_boom`` (boom, barrel and rod with the driven
prismatic pair). Figures:

- *sweep step*: one step of the continuation that traces a group's modes
  (:func:`linkage.kinematics.tracing._advance`), from every traced mode at one sweep angle to the
  next, over the whole 360-angle sweep, per step. For the triad twice: as traced (it lists its
  modes in closed form; Newton's method runs only where a listed mode jumps) and by Newton's
  method (the step of a group that cannot list its modes, e.g. a triad with a slider);
- *trace*: :func:`linkage.kinematics.tracing.trace_modes` over the sweep, per sweep angle;
- *Newton solve* at N = 1, 12, 360 positions: :func:`assur.generic.newton` from the traced mode
  interpolated half-way between sweep angles, and :meth:`assur.generic.NewtonGroup.position` (the
  solve with its closure and conditioning checks);
- ``linkage.load`` of both schemes (the assembly plans trace the groups);
- with ``--enumerate``: ``linkage enumerate six_bar --newton``, wall time of one run each way.

Every figure is the median over paired rounds (both paths timed in the same round, alternating
which goes first); the ratio is taken per round, then medianed.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse
import platform
import statistics
import subprocess
import sys
import time
from datetime import date
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import assur.fused  # noqa: E402
import linkage  # noqa: E402
import linkage.kinematics.assembly as assembly  # noqa: E402
from assur.generic import newton  # noqa: E402
from linkage.kinematics import tracing  # noqa: E402
from machine import cpu_model  # noqa: E402

SCHEMES = ("six_bar_class3", "cylinder_boom")
SIZES = (1, 12, 360)
PATHS = ("pairwise", "fused")


def use(path: str) -> None:
    assur.fused.FUSED = path == "fused"


def captured_sweep(name: str) -> dict:
    """Load ``name`` and keep the arguments of its traced group's sweep (group, sweep angles, known
    poses, the known poses at any angle, periodic) and the traced modes."""
    kept = {}
    original = assembly.trace_modes

    def spy(group, phi, known, known_at, periodic):
        traces = original(group, phi, known, known_at, periodic)
        kept.update(group=group, phi=phi, known=known, known_at=known_at, periodic=periodic, traces=traces)
        return traces

    assembly.trace_modes = spy
    try:
        linkage.load(name)
    finally:
        assembly.trace_modes = original
    return kept


def _wrap(angle):
    return (angle + np.pi) % (2 * np.pi) - np.pi


def sweep_steps(sweep: dict, listed: bool):
    """A callable that takes every step of the traced modes over the sweep (``_advance`` from the
    modes at angle m to angle m + 1), and the number of steps."""
    group, known, traces = sweep["group"], sweep["known"], sweep["traces"]
    links, size = group.links, float(np.max(group.size))
    rows = {k: np.stack([t.rows[k] for t in traces], axis=1) for k in links}        # (M, C, 3)
    M = len(sweep["phi"])
    options = group.modes(known) if listed else None
    steps = [m for m in range(M - 1) if tracing.finite_poses({k: v[m] for k, v in rows.items()}).any()]

    def run():
        for m in steps:
            current = {k: v[m] for k, v in rows.items()}
            previous = {k: v[m - 1] for k, v in rows.items()} if m else None
            here = {k: v[m + 1:m + 2] for k, v in known.items()}
            at = None if options is None else ({k: v[m + 1:m + 2] for k, v in options[0].items()},
                                               options[1][m + 1:m + 2])
            tracing._advance(group, current, here, at, size, previous)
    return run, len(steps)


def solve_case(sweep: dict, N: int):
    """Known poses and starts at N angles half-way between sweep angles (the declared mode, its
    neighbours' mean as the start)."""
    group, phi, traces = sweep["group"], sweep["phi"], sweep["traces"]
    trace = traces[0]
    M = len(phi)
    ok = [m for m in range(M - 1) if tracing.finite_poses({k: v[m:m + 2] for k, v in trace.rows.items()}).all()]
    picks = np.asarray(ok)[np.linspace(0, len(ok) - 1, N).astype(int)]
    angles = 0.5 * (phi[picks] + phi[picks + 1])
    known = sweep["known_at"](angles)
    start = {}
    for k, v in trace.rows.items():
        a, b = v[picks], v[picks + 1]
        mid = 0.5 * (a + b)
        mid[:, 2] = a[:, 2] + 0.5 * _wrap(b[:, 2] - a[:, 2])
        start[k] = mid
    return group, known, start


def timed(fn, repeat: int) -> float:
    """CPU seconds per call (this process's: on a shared machine the wall clock also counts the
    time other jobs hold the core): the best of three runs of ``repeat`` calls."""
    best = np.inf
    for _ in range(3):
        t = time.process_time()
        for _ in range(repeat):
            fn()
        best = min(best, (time.process_time() - t) / repeat)
    return best


def paired(fn_of_path, rounds: int, repeat: int) -> dict:
    """Median seconds per call of each path and the median per-round ratio pairwise / fused."""
    seconds = {p: [] for p in PATHS}
    ratios = []
    for r in range(rounds):
        got = {}
        for p in (PATHS if r % 2 == 0 else PATHS[::-1]):
            use(p)
            got[p] = timed(fn_of_path(p), repeat)
            seconds[p].append(got[p])
        ratios.append(got["pairwise"] / got["fused"])
    use("fused")
    return {"pairwise": statistics.median(seconds["pairwise"]), "fused": statistics.median(seconds["fused"]),
            "ratio": statistics.median(ratios)}


def enumerate_time(path: str) -> tuple[float, float]:
    """Wall and CPU seconds (user + system, of the child) of one ``linkage enumerate six_bar --newton``."""
    code = ("import sys, assur.fused; assur.fused.FUSED = %r; from linkage.cli import main; "
            "sys.exit(main(['enumerate', 'six_bar', '--newton']))" % (path == "fused"))
    before, t = os.times(), time.perf_counter()
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    after = os.times()
    return time.perf_counter() - t, (after.children_user - before.children_user) + (after.children_system
                                                                                     - before.children_system)


def fmt(seconds: float) -> str:
    if seconds >= 1:
        return f"{seconds:.2f} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds * 1e6:.0f} us"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 rounds, fewer repeats")
    parser.add_argument("--enumerate", action="store_true", help="also time 'linkage enumerate six_bar --newton'")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results_newton.md"))
    args = parser.parse_args(argv)
    rounds = 3 if args.quick else 7
    began = time.perf_counter()
    rows = []

    def record(what: str, result: dict) -> None:
        rows.append((what, result))
        print(f"{what:58s} pairwise {fmt(result['pairwise']):>9s}  fused {fmt(result['fused']):>9s}  "
              f"x{result['ratio']:.1f}", flush=True)

    use("fused")
    sweeps = {name: captured_sweep(name) for name in SCHEMES}
    for name in SCHEMES:
        sweep = sweeps[name]
        label = f"{name} {sweep['group']!r}"
        variants = [("Newton", False)] + ([("listed modes", True)] if sweep["group"].modes(sweep["known"]) else [])
        for how, listed in variants:
            run, count = sweep_steps(sweep, listed)
            result = paired(lambda p: run, rounds, 1)
            record(f"{label}: sweep step ({how})", {k: (v / count if k != "ratio" else v) for k, v in result.items()})
        M = len(sweep["phi"])
        result = paired(lambda p: (lambda: tracing.trace_modes(sweep["group"], sweep["phi"], sweep["known"],
                                                               sweep["known_at"], sweep["periodic"])), rounds, 1)
        record(f"{label}: trace_modes, per sweep angle", {k: (v / M if k != "ratio" else v) for k, v in result.items()})
        for N in SIZES:
            group, known, start = solve_case(sweep, N)
            repeat = max(1, int(200 / N ** 0.5 / (1 if not args.quick else 4)))
            record(f"{label}: newton(), N = {N}",
                   paired(lambda p: (lambda: newton(group, known, start)), rounds, repeat))
            record(f"{label}: position(start=...), N = {N}",
                   paired(lambda p: (lambda: group.position(known, start=start)), rounds, repeat))
    for name in SCHEMES:
        record(f"linkage.load({name!r})", paired(lambda p: (lambda: linkage.load(name)), rounds, 1))
    enumerated = None
    if args.enumerate:
        enumerated = {p: enumerate_time(p) for p in PATHS}
        print(f"linkage enumerate six_bar --newton: wall/CPU pairwise {enumerated['pairwise'][0]:.0f}/"
              f"{enumerated['pairwise'][1]:.0f} s, fused {enumerated['fused'][0]:.0f}/{enumerated['fused'][1]:.0f} s",
              flush=True)
    elapsed = time.perf_counter() - began
    lines = [
        "# Groups solved by Newton's method: fused residual and Jacobian (issue 24 item 2)",
        "",
        f"Written by `python benchmarks/bench_newton.py{' --quick' if args.quick else ''}"
        f"{' --enumerate' if args.enumerate else ''}` on {date.today().isoformat()} in {elapsed:.0f} s.",
        f"Machine: {os.cpu_count()} cores, CPU {cpu_model()}; Python {platform.python_version()}, numpy {np.__version__}.",
        "The machine was shared with other jobs while this ran (loaded): times are this process's CPU",
        "time (the wall clock also counts the time other jobs held the core), still noisy; the ratios",
        f"are taken within paired rounds ({rounds} rounds, order alternating) and medianed.",
        "",
        "*pairwise*: residual and Jacobian assembled pair by pair (`assur.fused.FUSED = False`, the code",
        "as it was); *fused*: `assur.fused` (one array expression per kind of pair). Both give the same",
        "numbers (tests/test_newton_fused.py). A sweep step is one step of the continuation that traces",
        "the group's modes over the 360-angle sweep (every traced mode at once); *Newton* takes it by",
        "Newton's method, *listed modes* as the RRR triad does (its modes listed in closed form).",
        "",
        "| measurement | pairwise | fused | pairwise / fused |",
        "|---|---:|---:|---:|",
    ]
    lines += [f"| {what} | {fmt(r['pairwise'])} | {fmt(r['fused'])} | {r['ratio']:.1f} |" for what, r in rows]
    if enumerated:
        for n, what in enumerate(("wall", "CPU")):
            lines += [f"| `linkage enumerate six_bar --newton`, {what} time (one run each) | "
                      f"{enumerated['pairwise'][n]:.0f} s | {enumerated['fused'][n]:.0f} s | "
                      f"{enumerated['pairwise'][n] / enumerated['fused'][n]:.1f} |"]
    Path(args.out).write_text("\n".join(lines) + "\n")
    print(f"wrote {args.out} ({elapsed:.0f} s)")


if __name__ == "__main__":
    main()
