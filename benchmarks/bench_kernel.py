"""The compiled kinematics kernel against the general path and the hand-fused four-bar (issue 24 item 1).

Run from the repository root::

    python benchmarks/bench_kernel.py            # 9 paired rounds per N, about a minute
    python benchmarks/bench_kernel.py --rounds 5
    python benchmarks/bench_kernel.py --compile-times   # numba: compile in a first process, load in a second

Contenders, the four-bar of ``schemes/four_bar.toml``, full kinematics (poses, first and second
analogs, statuses, conditioning, error bounds) at N = 12, 360, 10,000 and 100,000 input angles:

- **general**: ``linkage.analyze(mech, phi, order=2, on_failure="mask")`` with the kernel off
  (``motion.USE_KERNEL = False``: ``run_blocks`` and each group's ``Dyad.solve``, plus the
  continuity and jump checks);
- **kernel**: ``run_kernel(mech, phi, 2)`` (linkage/kinematics/kernel.py, warm: compiled once;
  the numpy kernel: ``LINKAGE_NUMBA=0`` in this process);
- **numba kernel**: the same kernel written as one numba loop (linkage/kinematics/kernel_numba.py,
  the ``fast`` extra; compiled before timing; skipped where numba is not installed);
- **kernel + points**: the kernel, then the points A, B, E and their analogs from its poses
  (what the hand-fused kernel gives, without statuses or error bounds);
- **hand-fused**: ``benchmarks/handfused.py`` ``fourbar_kinematics`` (A, B, E and the link angles
  with analogs; no statuses, conditioning or bounds).

Each round runs every contender once, in an order rotated by one each round; a call is repeated
until it has run for about 20 ms and timed per call. Figures are medians over rounds; ratios are
computed within each round, then medianed. Writes ``benchmarks/results_kernel.md``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"
os.environ["LINKAGE_NUMBA"] = "0"      # run_kernel and analyze: the numpy kernel (the numba one is its own contender)

import argparse
import datetime
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

BENCH_DIR = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH_DIR.parent))
sys.path.insert(0, str(BENCH_DIR))

import handfused  # noqa: E402
from machine import cpu_model  # noqa: E402

import linkage  # noqa: E402
from assur.base import point_analogs  # noqa: E402
import linkage.kinematics.motion as motion  # noqa: E402
from linkage.kinematics.kernel import Kernel, kernel_source, run_kernel  # noqa: E402
from linkage.kinematics.kernel_numba import TieredKernel  # noqa: E402
from linkage.kinematics.motion import BranchWarning  # noqa: E402
from linkage.structure import structure_of  # noqa: E402

SIZES = (12, 360, 10_000, 100_000)
POINTS = ("A", "B", "E")


def numba_kernel(mech):
    """The four-bar's kernel on numba (compiled now), or None where numba is not installed."""
    os.environ["LINKAGE_NUMBA"] = "1"
    try:
        kernel = Kernel(mech, structure_of(mech), 2)
        fn = kernel.function(kernel.branches(np.zeros(1)))[0]
    finally:
        os.environ["LINKAGE_NUMBA"] = "0"
    return kernel if isinstance(fn, TieredKernel) and fn.compile() else None


def contenders(mech, phi, fast=None):
    L = mech.links
    geo = {"OA": L["1"].points["A"][0], "AB": L["2"].points["B"][0], "CB": L["3"].points["B"][0],
           "C": tuple(L["0"].points["C"]), "E_local": tuple(L["2"].points["E"])}

    def general():
        motion.USE_KERNEL = False
        try:
            return linkage.analyze(mech, phi, order=2, on_failure="mask")
        finally:
            motion.USE_KERNEL = True

    def kernel():
        return run_kernel(mech, phi, 2)

    def kernel_points():
        got = run_kernel(mech, phi, 2)
        out = {}
        for p in POINTS:
            link = mech.point_link(p)
            local = mech.links[link].points[p]
            pose = got["poses"][link]
            c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
            rho = np.column_stack([c * local[0] - s * local[1], s * local[0] + c * local[1]])
            out[p] = (pose[:, :2] + rho, *point_analogs(pose, got["first"][link], got["second"][link], local, rho))
        return got, out

    def hand():
        return handfused.fourbar_kinematics(phi, **geo)

    got = {"general": general, "kernel": kernel, "kernel + points": kernel_points, "hand-fused": hand}
    if fast is not None:
        got["numba kernel"] = lambda: fast(phi)
    return got


def per_call(fn, budget=0.02) -> float:
    """Seconds per call of ``fn``, repeated until about ``budget`` s have passed."""
    reps, elapsed = 0, 0.0
    start = time.perf_counter()
    while elapsed < budget or reps < 2:
        fn()
        reps += 1
        elapsed = time.perf_counter() - start
    return elapsed / reps


def measure(rounds: int) -> dict:
    mech = linkage.load("four_bar")
    fast = numba_kernel(mech)
    out = {}
    for n in SIZES:
        phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        fns = contenders(mech, phi, fast)
        for fn in fns.values():           # warm-up: compile the kernel, fill the caches
            fn()
        names = list(fns)
        times = {k: [] for k in names}
        for r in range(rounds):
            order = names[r % len(names):] + names[:r % len(names)]
            for k in order:
                times[k].append(per_call(fns[k]))
        ratios = {
            "general / kernel": [g / k for g, k in zip(times["general"], times["kernel"])],
            "kernel / hand-fused": [k / h for k, h in zip(times["kernel"], times["hand-fused"])],
            "(kernel + points) / hand-fused": [k / h for k, h in zip(times["kernel + points"], times["hand-fused"])],
        }
        if "numba kernel" in times:
            ratios["kernel / numba"] = [k / f for k, f in zip(times["kernel"], times["numba kernel"])]
            ratios["numba / hand-fused"] = [f / h for f, h in zip(times["numba kernel"], times["hand-fused"])]
        out[n] = ({k: statistics.median(v) for k, v in times.items()},
                  {k: statistics.median(v) for k, v in ratios.items()})
        print(f"N = {n}: " + ", ".join(f"{k} {v * 1e3:.3f} ms" for k, v in out[n][0].items())
              + " | " + ", ".join(f"{k} {v:.2f}" for k, v in out[n][1].items()), flush=True)
    return out


_COMPILE_SCRIPT = """
import time
start = time.perf_counter()
import numpy as np, linkage, numba
from linkage.kinematics.kernel import kernel_for
mech = linkage.load("four_bar")
kernel = kernel_for(mech, 2)
ready = time.perf_counter()
kernel(np.linspace(0.0, 1.0, 12))
done = time.perf_counter()
assert kernel.function(kernel.branches(np.zeros(1)))[0].jitted is not None
print(ready - start, done - ready)
"""


def compile_times(runs: int = 3) -> list[tuple[float, float]] | None:
    """(imports, first kernel call) seconds of fresh processes sharing one empty kernel cache: the
    first compiles the four-bar's numba kernel, the next ones load it (None without numba)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return None
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "LINKAGE_NUMBA": "1", "LINKAGE_CACHE_DIR": cache}
        out = []
        for _ in range(runs):
            done = subprocess.run([sys.executable, "-c", _COMPILE_SCRIPT], capture_output=True, text=True, env=env,
                                  cwd=BENCH_DIR.parent, check=True)
            first, second = done.stdout.split()
            out.append((float(first), float(second)))
    return out


def write(results: dict, rounds: int, path: Path, compiled: list | None = None) -> None:
    mech = linkage.load("four_bar")
    source = kernel_source(mech, 2)
    calls = sum("np." in line for line in source.splitlines())
    lines = [
        "# The compiled kinematics kernel: four-bar full kinematics",
        "",
        f"Written by `python benchmarks/bench_kernel.py` on {datetime.date.today()} ({cpu_model()}, "
        f"Python {platform.python_version()}, numpy {np.__version__}, one thread).",
        "",
        "**Measured on a loaded machine** (2 cores shared by 4 agents at the time): the absolute times are "
        "noisy; the ratios, taken within paired rounds and medianed, are the figures to read.",
        f"{rounds} paired rounds per N, contenders in a rotated order, each call repeated for ~20 ms.",
        "",
        "- general: `linkage.analyze(mech, phi, order=2, on_failure=\"mask\")`",
        "- kernel: `linkage.kinematics.kernel.run_kernel(mech, phi, 2)` (warm; the same poses, analogs, "
        "statuses, conditioning and error bounds)",
        "- kernel + points: the kernel, then A, B, E with their analogs",
        "- hand-fused: `benchmarks/handfused.py` `fourbar_kinematics` (A, B, E, link angles and analogs; "
        "no statuses, conditioning or bounds)",
        "",
        f"The four-bar's kernel (order 2) is {len(source.splitlines())} lines of straight-line numpy, "
        f"{calls} numpy calls per block of positions.",
        "",
        "| N | general ms | kernel ms | kernel + points ms | hand-fused ms | general / kernel | "
        "kernel / hand-fused | (kernel + points) / hand-fused | kernel M positions/s |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for n, (t, r) in results.items():
        lines.append(f"| {n} | {t['general'] * 1e3:.3f} | {t['kernel'] * 1e3:.3f} | {t['kernel + points'] * 1e3:.3f} | "
                     f"{t['hand-fused'] * 1e3:.3f} | {r['general / kernel']:.2f} | {r['kernel / hand-fused']:.2f} | "
                     f"{r['(kernel + points) / hand-fused']:.2f} | {n / t['kernel'] / 1e6:.2f} |")
    if any("numba kernel" in t for t, _ in results.values()):
        lines += [
            "",
            "With numba (`pip install \".[fast]\"`): the same kernel as one numba loop "
            "(linkage/kinematics/kernel_numba.py), called through the same `Kernel` (result dicts included).",
            "",
            "| N | numba kernel ms | numpy kernel / numba | numba / hand-fused | numba M positions/s |",
            "|---:|---:|---:|---:|---:|",
        ]
        for n, (t, r) in results.items():
            lines.append(f"| {n} | {t['numba kernel'] * 1e3:.4f} | {r['kernel / numba']:.2f} | "
                         f"{r['numba / hand-fused']:.2f} | {n / t['numba kernel'] / 1e6:.2f} |")
    if compiled:
        lines += ["", "numba compile, fresh processes sharing one empty kernel cache (imports s, first kernel call s): "
                  + "; ".join(f"{a:.2f}, {b:.3f}" for a, b in compiled)
                  + " -- the first compiles, the next load numba's cache (their first call is mostly numba's "
                  "own start-up)."]
    path.write_text("\n".join(lines) + "\n")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--out", type=Path, default=BENCH_DIR / "results_kernel.md")
    parser.add_argument("--compile-times", action="store_true", help="only time numba's compile and cache load")
    args = parser.parse_args(argv)
    compiled = compile_times()
    if compiled:
        print("numba (imports s, first call s), first process compiles, next ones load: "
              + "; ".join(f"{a:.2f}, {b:.3f}" for a, b in compiled), flush=True)
    if args.compile_times:
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        results = measure(args.rounds)
    write(results, args.rounds, args.out, compiled)
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
