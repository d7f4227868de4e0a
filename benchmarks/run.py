"""The library's speed against its peers and its goals, in one command.

Run from the repository root::

    python benchmarks/run.py --quick      # N = 1e5 positions, 5 paired rounds: under 3 min on 2 cores
    python benchmarks/run.py              # N = 1e6 positions, 7 paired rounds: about 9 min
    python benchmarks/run.py --quick --profile   # and cProfile of our four-bar into RESULTS.md

It writes ``benchmarks/RESULTS.md`` (``--out PATH``) and prints as its last stdout line one JSON
object with every figure (null where it cannot be measured; the reason goes to stderr).

How it measures: one thread for every numeric library (``OMP_NUM_THREADS=1`` set before numpy is
imported, and for every subprocess). Every contender runs once per *paired round*, in an order
rotated by one each round, so the noise of a shared machine hits all of them alike; a figure is
the median over rounds, and a ratio is computed within each round and then medianed. The peers
(pylinkage 1.3.0 with and without numba, in venvs created under ``benchmarks/.venvs/`` on first
use) run in long-lived worker processes (``peer_worker.py``) that time one run per request, so
their run sits in the same round as ours. The peak memory is measured in a fresh subprocess with
``tracemalloc`` (numpy's allocations are traced by it).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse
import cProfile
import datetime
import io
import json
import platform
import pstats
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

BENCH_DIR = Path(__file__).resolve().parent
REPO = BENCH_DIR.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(BENCH_DIR))

import handfused
import peers

import linkage
from linkage.kinetostatics.reactions import solve_reactions

FOURBAR = "four_bar"
SHAPER = "slotted_link_two_dyad"
POINTS = ("A", "B", "E")
MEMORY_N = 1_000_000
VARIANTS, VARIANT_POSITIONS, VARIANT_SEED, VARIANT_SPREAD = 10_000, 12, 20240601, 0.2
SMALL_N, SMALL_CALLS = 12, 100
DEFAULT_SHAPER_SPEED = 10.0                          # rad/s, when the scheme declares no mean speed


@dataclass(frozen=True)
class Settings:
    """What one run measures and how long it may take."""

    quick: bool
    positions: int
    rounds: int
    trade_timeout: float
    venv_timeout: float = 150.0


def settings_for(quick: bool, rounds: int | None = None, positions: int | None = None) -> Settings:
    base = Settings(True, 100_000, 5, 60.0) if quick else Settings(False, 1_000_000, 7, 600.0)
    return Settings(base.quick, positions or base.positions, rounds or base.rounds, base.trade_timeout)


def progress(message: str) -> None:
    print(f"[bench] {message}", file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------
# the work that is timed
# ----------------------------------------------------------------------------------------------


def full_kinematics(mech: linkage.Mechanism, phi: np.ndarray) -> tuple[linkage.Motion, dict]:
    """Our full kinematics of the four-bar: the Motion and A, B, E with their analogs.

    Returns
    -------
    motion, points
        ``points[P] = (position, first, second)``, each (N, 2), m, m/rad, m/rad^2.
    """
    motion = linkage.analyze(mech, phi, order=2, on_failure="mask")
    return motion, {p: (motion.point(p), *motion.point_analogs(p)) for p in POINTS}


def positions_only(mech: linkage.Mechanism, phi: np.ndarray) -> dict:
    """Our positions of A, B, E, each (N, 2), m (order 0)."""
    motion = linkage.analyze(mech, phi, order=0, on_failure="mask")
    return {p: motion.point(p) for p in POINTS}


def shaper_speed(mech: linkage.Mechanism) -> tuple[float, str]:
    """The shaper's declared mean speed (rad/s), or :data:`DEFAULT_SHAPER_SPEED`, and where it came from."""
    from linkage.dynamics.spec import dynamics_of
    try:
        return float(dynamics_of(mech).mean_speed), "the scheme's [dynamics] mean_speed"
    except linkage.LinkageError as exc:
        return DEFAULT_SHAPER_SPEED, f"{DEFAULT_SHAPER_SPEED} rad/s ({exc})"


def shaper_reactions(mech: linkage.Mechanism, phi: np.ndarray, omega: float):
    """Kinematics (order 2, real speed) and reactions with inertia of the shaper."""
    motion = linkage.analyze(mech, phi, order=2, omega=omega, on_failure="mask")
    return solve_reactions(motion)


def fourbar_geometry(mech: linkage.Mechanism) -> dict:
    """The four-bar's lengths as ``handfused`` takes them: OA, AB, CB (m), C (m), E_local (m)."""
    links = mech.links
    return {"OA": links["1"].points["A"][0], "AB": links["2"].points["B"][0],
            "CB": links["3"].points["B"][0], "C": tuple(links["0"].points["C"]),
            "E_local": tuple(links["2"].points["E"])}


def variant_geometry(mech: linkage.Mechanism, count: int, seed: int, spread: float) -> dict:
    """``count`` four-bars around the shipped one: OA, AB, CB and the frame's C each scaled by a
    factor drawn uniformly in [1 - spread, 1 + spread] (fixed seed); a link's every point scales
    with its length (E and S2 with AB, S3 with CB).

    Returns
    -------
    dict of link name -> {point name -> ndarray (count, 2)}, local coordinates, m.
    """
    rng = np.random.default_rng(seed)
    factors = rng.uniform(1 - spread, 1 + spread, size=(4, count))
    scale = {"1": factors[0], "2": factors[1], "3": factors[2]}
    geometry = {}
    for name, link in mech.links.items():
        geometry[name] = {}
        for point, xy in link.points.items():
            local = np.tile(np.asarray(xy, dtype=float), (count, 1))
            if name in scale:
                local *= scale[name][:, None]
            elif point == "C":
                local[:, 0] *= factors[3]
            geometry[name][point] = local
    return geometry


# ----------------------------------------------------------------------------------------------
# contenders and paired rounds
# ----------------------------------------------------------------------------------------------


@dataclass
class Contender:
    """One timed thing: ``run()`` does it once and returns its duration per ``per`` positions, s."""

    key: str
    label: str
    positions: int
    run: Callable[[], float]
    times: list[float] = field(default_factory=list)

    def rate(self) -> float | None:
        """Median positions per second over the rounds."""
        return self.positions / statistics.median(self.times) if self.times else None


def timed(fn: Callable[[], object]) -> Callable[[], float]:
    def run() -> float:
        t0 = time.perf_counter()
        fn()
        return time.perf_counter() - t0
    return run


def median_call(fn: Callable[[], object], calls: int) -> Callable[[], float]:
    """The median duration of ``calls`` separate calls, s (one round's figure of a short call)."""
    def run() -> float:
        durations = []
        for _ in range(calls):
            t0 = time.perf_counter()
            fn()
            durations.append(time.perf_counter() - t0)
        return statistics.median(durations)
    return run


def our_contenders(settings: Settings, notes: dict) -> list[Contender]:
    """Our four-bar, positions and full, the hand-fused kernel, the shaper, N = 12 and the variants."""
    n = settings.positions
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    four = linkage.load(FOURBAR)
    shaper = linkage.load(SHAPER)
    omega, source = shaper_speed(shaper)
    notes["shaper_speed"] = source
    geo = fourbar_geometry(four)
    phi12 = np.linspace(0.0, 2.0 * np.pi, SMALL_N, endpoint=False)
    out = [
        Contender("fourbar_kinematics", "ours, full kinematics", n, timed(lambda: full_kinematics(four, phi))),
        Contender("fourbar_positions", "ours, positions only", n, timed(lambda: positions_only(four, phi))),
        Contender("handfused_kinematics", "hand-fused numpy, full kinematics", n,
                  timed(lambda: handfused.fourbar_kinematics(phi, **geo))),
        Contender("handfused_positions", "hand-fused numpy, positions only", n,
                  timed(lambda: handfused.fourbar_positions(phi, **geo))),
        Contender("shaper_reactions", "ours, shaper kinematics + reactions", n,
                  timed(lambda: shaper_reactions(shaper, phi, omega))),
        Contender("fourbar_call_n12", "ours, full kinematics, one call at N = 12", SMALL_N,
                  median_call(lambda: full_kinematics(four, phi12), SMALL_CALLS)),
    ]
    analyze_variants = getattr(linkage, "analyze_variants", None)
    if analyze_variants is None:
        notes["variants_kinematics_per_s"] = "linkage.analyze_variants does not exist (yet)"
    else:
        geometry = variant_geometry(four, VARIANTS, VARIANT_SEED, VARIANT_SPREAD)
        out.append(Contender("variants_kinematics", "ours, 10 000 four-bar variants x 12 positions, one call",
                             VARIANTS * SMALL_N,
                             timed(lambda: analyze_variants(four, phi12, geometry, order=2, on_failure="mask"))))
    return out


def warm(contenders: list[Contender], notes: dict) -> list[Contender]:
    """Run each contender once untimed; one that fails is dropped with the reason in ``notes``."""
    kept = []
    for c in contenders:
        try:
            c.run()
        except Exception as exc:  # noqa: BLE001 - any failure of a contender is reported, not fatal
            notes[c.key + "_per_s"] = f"{c.label} failed: {type(exc).__name__}: {exc}"
            continue
        kept.append(c)
    return kept


def paired_rounds(contenders: list[Contender], rounds: int, notes: dict) -> None:
    """Each round runs every contender once, the order rotated by one each round."""
    bar = _progress_bar(rounds * len(contenders))
    for r in range(rounds):
        k = r % len(contenders)
        for c in contenders[k:] + contenders[:k]:
            try:
                c.times.append(c.run())
            except Exception as exc:  # noqa: BLE001 - a peer that dies mid-run loses its figure
                notes[c.key + "_per_s"] = f"{c.label} failed in round {r + 1}: {exc}"
                c.times.append(float("nan"))
            bar.update(1)
    bar.close()
    for c in contenders:
        if any(not np.isfinite(t) for t in c.times):
            c.times = []


def _progress_bar(total: int):
    try:
        from tqdm import tqdm
        return tqdm(total=total, file=sys.stderr, desc="paired rounds", unit="run")
    except ImportError:
        class Plain:
            done = 0

            def update(self, k):
                self.done += k
                progress(f"{self.done}/{total} runs")

            def close(self):
                pass
        return Plain()


def paired_ratio(faster: Contender | None, slower: Contender | None) -> float | None:
    """Median over rounds of (positions/s of ``faster``) / (positions/s of ``slower``)."""
    if faster is None or slower is None or not faster.times or not slower.times:
        return None
    per_round = [(faster.positions / a) / (slower.positions / b) for a, b in zip(faster.times, slower.times)]
    return statistics.median(per_round)


# ----------------------------------------------------------------------------------------------
# peers
# ----------------------------------------------------------------------------------------------


def write_reference(path: Path, n: int) -> None:
    """Our four-bar at phi = 2 pi k / n: A, B, E (m) and their analogs, for the peers' check."""
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    _, points = full_kinematics(linkage.load(FOURBAR), phi)
    arrays = {"phi": phi}
    for p, (pos, first, second) in points.items():
        arrays.update({p: pos, "d" + p: first, "dd" + p: second})
    np.savez(path, **arrays)


PEER_TASKS = {
    "pylinkage_numba": [("kinematics", "pylinkage_numba_kinematics", "pylinkage + numba, full kinematics"),
                        ("positions", "pylinkage_numba_positions", "pylinkage + numba, positions only"),
                        ("kinematics_points", "pylinkage_numba_kinematics_points",
                         "pylinkage + numba, its call alone (points, no link angles)")],
    "pylinkage_plain": [("kinematics", "pylinkage_plain_kinematics", "pylinkage (no numba), full kinematics")],
}


def peer_contenders(workers: dict, n: int) -> list[Contender]:
    out = []
    for name, worker in workers.items():
        for task, key, label in PEER_TASKS[name]:
            out.append(Contender(key, label, n, lambda w=worker, t=task: w.seconds(t)))
    return out


def start_peers(settings: Settings, reference: Path, env: dict, notes: dict, jobs: dict) -> dict:
    """Wait for the venvs, start one worker per peer; those that fail are left out with the reason."""
    workers = {}
    for name, job in jobs.items():
        try:
            python = peers.finish_venv(job, settings.venv_timeout)
            workers[name] = peers.PeerWorker(python, reference, env)
        except peers.PeerUnavailable as exc:
            notes[name] = str(exc)
    return workers


def wait_peers(workers: dict, notes: dict, info: dict) -> dict:
    ready = {}
    for name, worker in workers.items():
        try:
            info[name] = worker.wait_ready(timeout=600.0)
            ready[name] = worker
            progress(f"{name}: ready ({info[name]['path']} path, largest difference to ours: "
                     f"{info[name]['check']})")
        except peers.PeerUnavailable as exc:
            notes[name] = str(exc)
    return ready


# ----------------------------------------------------------------------------------------------
# memory (a fresh subprocess) and profile
# ----------------------------------------------------------------------------------------------


def _array_bytes(arrays) -> int:
    """Sum of nbytes of distinct arrays (a buffer seen twice counts once)."""
    seen, total = set(), 0
    for a in arrays:
        if isinstance(a, np.ndarray):
            key = (a.__array_interface__["data"][0], a.nbytes)
            if key not in seen:
                seen.add(key)
                total += a.nbytes
    return total


def result_arrays(motion: linkage.Motion, points: dict) -> list[np.ndarray]:
    """Every array of a full-kinematics result: the Motion's and the points A, B, E with analogs."""
    arrays = [motion.status, motion.error_bound]
    for d in (motion.poses, motion.first, motion.second, motion.conditioning):
        arrays += list((d or {}).values())
    for triple in points.values():
        arrays += list(triple)
    return arrays


def memory_probe(n: int) -> dict:
    """Peak memory of our full kinematics of the four-bar at ``n`` positions (run in a fresh process).

    tracemalloc's peak over the call (numpy reports its allocations to tracemalloc), the
    growth of the peak resident set size (``ru_maxrss``) over the call, and the size of the
    result's arrays, bytes.
    """
    mech = linkage.load(FOURBAR)
    full_kinematics(mech, np.linspace(0.0, 1.0, 16))              # caches and lazy imports
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    motion, points = full_kinematics(mech, phi)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    kept = [a for a in result_arrays(motion, points) if a is not phi]
    return {"n": n, "peak_tracemalloc_bytes": peak, "maxrss_growth_bytes": (rss1 - rss0) * 1024,
            "result_bytes": _array_bytes(kept)}


def start_memory_probe(env: dict) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--memory-probe", str(MEMORY_N)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=str(REPO))


def finish_memory_probe(process: subprocess.Popen, notes: dict) -> dict | None:
    try:
        out, err = process.communicate(timeout=600)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        notes["peak_memory_1e6_bytes"] = "the memory probe took more than 600 s"
        return None
    if process.returncode != 0 or not out.strip():
        notes["peak_memory_1e6_bytes"] = f"the memory probe failed: {err.strip().splitlines()[-1:]}"
        return None
    return json.loads(out.strip().splitlines()[-1])


def profile_lines(positions: int) -> list[str]:
    """cProfile of our full kinematics of the four-bar at N = ``positions`` and N = 12, top 15 cumulative."""
    mech = linkage.load(FOURBAR)
    lines = []
    for n, calls in ((positions, 1), (SMALL_N, 200)):
        phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        full_kinematics(mech, phi)
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(calls):
            full_kinematics(mech, phi)
        profiler.disable()
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).strip_dirs().sort_stats("cumulative").print_stats(15)
        body = text.getvalue().strip().splitlines()
        start = next((i for i, line in enumerate(body) if line.lstrip().startswith("ncalls")), 0)
        lines += [f"### cProfile: four-bar full kinematics, N = {n}, {calls} call(s), top 15 by cumulative time",
                  "", "```", *[line.rstrip() for line in body[max(0, start - 2):]], "```", ""]
    return lines


# ----------------------------------------------------------------------------------------------
# trade.py (another benchmark, appended when present)
# ----------------------------------------------------------------------------------------------

_TRADE_CHILD = """
import json, sys
sys.path.insert(0, sys.argv[1])
import trade
run = getattr(trade, "run", None)
if not callable(run):
    print("benchmarks/trade.py has no run(quick) function", file=sys.stderr)
    sys.exit(3)
print(json.dumps([str(line) for line in run(sys.argv[2] == "quick", images=None)]))
"""


def trade_lines(settings: Settings, env: dict, notes: dict) -> list[str]:
    """Lines of ``benchmarks/trade.py``'s ``run(quick)``, run in a subprocess time-boxed to the settings."""
    path = BENCH_DIR / "trade.py"
    if not path.is_file():
        return []
    progress(f"benchmarks/trade.py (at most {settings.trade_timeout:.0f} s)")
    try:
        done = subprocess.run([sys.executable, "-c", _TRADE_CHILD, str(BENCH_DIR), "quick" if settings.quick else "full"],
                              check=False, capture_output=True, text=True, timeout=settings.trade_timeout, env=env, cwd=str(REPO))
    except subprocess.TimeoutExpired:
        notes["trade"] = f"benchmarks/trade.py took more than {settings.trade_timeout:.0f} s; its lines are left out"
        return []
    if done.returncode != 0 or not done.stdout.strip():
        tail = " | ".join(done.stderr.strip().splitlines()[-3:])
        notes["trade"] = f"benchmarks/trade.py failed (exit {done.returncode}): {tail}"
        return []
    return json.loads(done.stdout.strip().splitlines()[-1])


# ----------------------------------------------------------------------------------------------
# figures and goals
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Goal:
    key: str
    text: str
    target: float
    at_least: bool
    unit: str = ""


GOALS = (
    Goal("kinematics_vs_pylinkage_numba", "full kinematics >= 2x pylinkage + numba", 2.0, True, "x"),
    Goal("kinematics_vs_pylinkage_plain", "full kinematics >= 30x pylinkage without numba", 30.0, True, "x"),
    Goal("positions_vs_pylinkage_numba", "positions only >= pylinkage + numba", 1.0, True, "x"),
    Goal("handfused_over_ours_kinematics", "within 1.5x of the hand-fused kernel (hand-fused / ours <= 1.5)",
         1.5, False, "x"),
    Goal("shaper_reactions_per_s", "shaper kinematics + reactions >= 1 M positions/s", 1e6, True, "positions/s"),
    Goal("fourbar_call_n12_s", "one call at N = 12 <= 0.1 ms", 1e-4, False, "s"),
    Goal("variants_kinematics_per_s", "variant batches >= 5 M position-variants/s", 5e6, True, "position-variants/s"),
    Goal("peak_memory_over_result", "peak memory at 1e6 positions <= 2x the result's size", 2.0, False, "x"),
)


def goal_status(goal: Goal, value: float | None) -> dict:
    """Met or not, and the factor by which a missed goal is missed (>= 1)."""
    if value is None or not np.isfinite(value):
        return {"value": None, "goal": goal.text, "met": None, "missed_by_factor": None}
    met = value >= goal.target if goal.at_least else value <= goal.target
    factor = (goal.target / value if goal.at_least else value / goal.target) if value > 0 else float("inf")
    return {"value": value, "goal": goal.text, "met": bool(met), "missed_by_factor": None if met else factor}


def figures(contenders: dict[str, Contender], memory: dict | None, peer_info: dict) -> dict:
    """Every figure of the JSON line (floats or None)."""
    c = contenders.get

    def rate(key):
        return c(key).rate() if c(key) else None

    out = {
        "fourbar_kinematics_per_s": rate("fourbar_kinematics"),
        "fourbar_positions_per_s": rate("fourbar_positions"),
        "pylinkage_numba_kinematics_per_s": rate("pylinkage_numba_kinematics"),
        "pylinkage_plain_kinematics_per_s": rate("pylinkage_plain_kinematics"),
        "pylinkage_numba_positions_per_s": rate("pylinkage_numba_positions"),
        "pylinkage_numba_kinematics_points_per_s": rate("pylinkage_numba_kinematics_points"),
        "handfused_kinematics_per_s": rate("handfused_kinematics"),
        "handfused_positions_per_s": rate("handfused_positions"),
        "shaper_reactions_per_s": rate("shaper_reactions"),
        "fourbar_call_n12_s": statistics.median(c("fourbar_call_n12").times) if c("fourbar_call_n12") and
        c("fourbar_call_n12").times else None,
        "variants_kinematics_per_s": rate("variants_kinematics"),
        "kinematics_vs_pylinkage_numba": paired_ratio(c("fourbar_kinematics"), c("pylinkage_numba_kinematics")),
        "kinematics_vs_pylinkage_numba_points": paired_ratio(c("fourbar_kinematics"),
                                                             c("pylinkage_numba_kinematics_points")),
        "kinematics_vs_pylinkage_plain": paired_ratio(c("fourbar_kinematics"), c("pylinkage_plain_kinematics")),
        "positions_vs_pylinkage_numba": paired_ratio(c("fourbar_positions"), c("pylinkage_numba_positions")),
        "kinematics_vs_handfused": paired_ratio(c("fourbar_kinematics"), c("handfused_kinematics")),
        "handfused_over_ours_kinematics": paired_ratio(c("handfused_kinematics"), c("fourbar_kinematics")),
        "positions_vs_handfused": paired_ratio(c("fourbar_positions"), c("handfused_positions")),
    }
    peak = memory and memory.get("peak_tracemalloc_bytes")
    result = memory and memory.get("result_bytes")
    out["peak_memory_1e6_bytes"] = float(peak) if peak else None
    out["result_1e6_bytes"] = float(result) if result else None
    out["peak_memory_over_result"] = peak / result if peak and result else None
    out["maxrss_growth_1e6_bytes"] = float(memory["maxrss_growth_bytes"]) if memory else None
    for name, info in peer_info.items():
        out[f"{name}_max_position_difference_m"] = info["check"].get("positions")
        out[f"{name}_max_first_difference_m"] = info["check"].get("first")
        out[f"{name}_max_second_difference_m"] = info["check"].get("second")
    return out


# ----------------------------------------------------------------------------------------------
# RESULTS.md
# ----------------------------------------------------------------------------------------------


def machine() -> dict:
    model = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"cpu": model, "cores": os.cpu_count(), "usable_cores": usable, "python": platform.python_version(),
            "numpy": np.__version__, "platform": platform.platform()}


def fmt(value: float | None, unit: str = "") -> str:
    if value is None:
        return "n/a"
    if unit == "s":
        return f"{value * 1e3:.3g} ms"
    if unit == "bytes":
        return f"{value / 2**20:.1f} MiB"
    if unit == "x":
        return f"{value:.3g}x"
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.3g}"


FIGURE_ROWS = (
    ("fourbar_kinematics_per_s", "ours, four-bar full kinematics", "positions/s"),
    ("fourbar_positions_per_s", "ours, four-bar positions only", "positions/s"),
    ("handfused_kinematics_per_s", "hand-fused numpy, full kinematics", "positions/s"),
    ("handfused_positions_per_s", "hand-fused numpy, positions only", "positions/s"),
    ("pylinkage_numba_kinematics_per_s", "pylinkage 1.3.0 + numba, full kinematics", "positions/s"),
    ("pylinkage_numba_kinematics_points_per_s", "pylinkage 1.3.0 + numba, its call alone (no link angles)",
     "positions/s"),
    ("pylinkage_numba_positions_per_s", "pylinkage 1.3.0 + numba, positions only", "positions/s"),
    ("pylinkage_plain_kinematics_per_s", "pylinkage 1.3.0 without numba, full kinematics", "positions/s"),
    ("shaper_reactions_per_s", "ours, shaper kinematics + reactions (inertia)", "positions/s"),
    ("fourbar_call_n12_s", "ours, one full-kinematics call at N = 12", "s"),
    ("variants_kinematics_per_s", "ours, 10 000 variants x 12 positions in one call", "position-variants/s"),
    ("peak_memory_1e6_bytes", "ours, peak memory of full kinematics at N = 1e6 (tracemalloc)", "bytes"),
    ("maxrss_growth_1e6_bytes", "ours, growth of the peak RSS over that call (ru_maxrss)", "bytes"),
    ("result_1e6_bytes", "the result's arrays at N = 1e6", "bytes"),
)


def _notes_blocks(old_text: str) -> dict[str, str]:
    """Hand-written profile paragraphs of a previous RESULTS.md, by goal key (kept across runs)."""
    pattern = re.compile(r"<!-- notes:(\w+) -->\n(.*?)<!-- /notes:\1 -->", re.DOTALL)
    return {m.group(1): m.group(2) for m in pattern.finditer(old_text)}


def goals_table(goals: dict) -> list[str]:
    lines = ["| goal | figure | value | met? | by how much |", "|---|---|---|---|---|"]
    for g in GOALS:
        s = goals[g.key]
        met = "n/a" if s["met"] is None else "yes" if s["met"] else "**no**"
        by = ""
        if s["met"] is False:
            by = (f"needs {s['missed_by_factor']:.3g}x more" if g.at_least
                  else f"{s['missed_by_factor']:.3g}x over the limit")
        unit = "" if g.unit in ("s", "x") or s["value"] is None else " " + g.unit
        lines.append(f"| {g.text} | `{g.key}` | {fmt(s['value'], g.unit)}{unit} | {met} | {by} |")
    return lines


SAME_WORK = """\
**Full kinematics of the four-bar** (`schemes/four_bar.toml`: O = (0, 0), C = (0.3, 0), OA = 0.1 m,
AB = 0.3 m, CB = 0.25 m, coupler point E 0.15 m from A at 30 deg CCW from AB, B on the left of the
directed line A -> C) at phi = 2 pi k / N, k = 0..N-1: the positions and the first and second
analogs (derivatives with respect to the crank angle; with omega = 1 rad/s and eps = 0 they are the
velocities and accelerations) of every link's angle and of the points A, B and E. Ours:
`linkage.analyze(m, phi, order=2, on_failure="mask")`, then `point(p)` and `point_analogs(p)` for
p in A, B, E (the link angles and their analogs are in the Motion's poses, first, second).
**Positions only**: `order=0` and `point(p)` for A, B, E (the poses hold the link angles too).
**Hand-fused**: `benchmarks/handfused.py`, the same quantities for this one mechanism in closed
form (positions only: A, B, E and the angles of links 2 and 3).
**pylinkage 1.3.0**: the same four-bar in its component API (Ground O and C, a Crank at A turned
2 pi / N per step from phi = 0, an RRRDyad B, a FixedDyad E); positions only is
`Linkage.step_fast`; full kinematics is `Linkage.step_fast_with_kinematics` with
`set_input_velocity(crank, omega=1, alpha=0)` (positions, velocities and accelerations of the
joints O, C, A, B, E) followed by the angles of links 2 and 3 and their first and second
derivatives from those points in vectorised numpy (pylinkage has no link angles); "its call
alone" times the pylinkage call without that last step. Without numba the faster of
`step_fast_with_kinematics` (then plain Python) and the generator `step_with_derivatives` is used
(the worker times both over 2000 steps at start-up). pylinkage 1.3.0 does not need numba: it is
its optional `numba` extra; without it pylinkage replaces `numba.njit` by a no-op decorator, so
the "plain" venv is simply one without numba (no NUMBA_DISABLE_JIT needed). pylinkage picks the
circle intersection nearest to the previous step's B (a marching simulation); ours and the
hand-fused kernel compute each position independently from the assembly rule.
**Shaper**: `slotted_link_two_dyad` (crank + RPR + PRP), `analyze(order=2, omega=w)` then
`solve_reactions` (gravity, inertia forces and moments, declared loads).
**Variants**: one call of `linkage.analyze_variants` for 10 000 four-bars (OA, AB, CB and the
frame's C each scaled by a factor uniform in [0.8, 1.2], seed fixed; every point of a link scales
with it) at 12 positions; positions that cannot be assembled count too.
**Peak memory**: in a fresh subprocess, tracemalloc's peak over one full-kinematics call at
N = 1e6 (numpy reports its allocations to tracemalloc), against the sum of nbytes of the
result's arrays (the Motion's poses, first, second, status, conditioning, error bound, and the
A, B, E arrays with their analogs)."""


def results_markdown(settings: Settings, command: str, wall: float, figs: dict, goals: dict,
                     peer_info: dict, notes: dict, contenders: dict, extra: dict) -> list[str]:
    m = machine()
    lines = ["# Benchmarks: speed against peers and goals", "",
             f"- date: {datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}",
             f"- machine: {m['cores']} cores ({m['usable_cores']} usable), CPU {m['cpu']}; {m['platform']}",
             (f"- Python {m['python']}, numpy {m['numpy']}, OMP_NUM_THREADS=1 (and every BLAS/numba thread "
             "count 1, for the subprocesses too)"),
             (f"- command: `{command}` ({'quick' if settings.quick else 'full'}: N = {settings.positions:,} "
             f"positions, {settings.rounds} paired rounds; wall time {wall:.0f} s)"),
             ("- the full run (`python benchmarks/run.py`: N = 1,000,000, 7 rounds) takes about 9 min on this "
             "machine (553 s measured), most of it pylinkage without numba"), "",
             "## Goals", "", *goals_table(goals), "",
             ("Ratios `X_vs_Y` are X's positions per second over Y's, computed within each round and then "
             "medianed (above 1: ours is faster)."), "",
             "## Figures", "", "| figure | value | unit |", "|---|---|---|"]
    for key, label, unit in FIGURE_ROWS:
        value = figs.get(key)
        shown = fmt(value, "s" if unit == "s" else "bytes" if unit == "bytes" else "")
        lines.append(f"| {label} (`{key}`) | {shown} | {'ms' if unit == 's' else 'MiB' if unit == 'bytes' else unit} |")
    lines += ["", "| ratio (within each round, medianed) | value |", "|---|---|"]
    for key in ("kinematics_vs_pylinkage_numba", "kinematics_vs_pylinkage_numba_points",
                "kinematics_vs_pylinkage_plain", "positions_vs_pylinkage_numba", "kinematics_vs_handfused",
                "handfused_over_ours_kinematics", "positions_vs_handfused", "peak_memory_over_result"):
        lines.append(f"| `{key}` | {fmt(figs.get(key), 'x')} |")
    lines += ["", "Per-round times (s; the per-call median for N = 12):", "", "| contender | times per round |",
              "|---|---|"]
    for c in contenders.values():
        lines.append(f"| {c.label} | {', '.join(f'{t:.4g}' for t in c.times) or 'n/a'} |")
    lines += ["", "## Same work", "", SAME_WORK, "", "## How the rounds are paired", "",
              ("Every contender, ours in this process and each peer in its own long-lived worker process, runs "
              "once per round; the order of the contenders is rotated by one from one round to the next, so "
              "each one takes every slot of the round once and a slow spell of the shared machine hits all of "
              "them. A peer's run is requested by this process and timed inside the worker (no start-up, "
              "import or compile time: the worker compiles and checks before the rounds). A ratio pairs the "
              "two contenders' runs of the same round; the figure is the median over rounds."), ""]
    lines += ["## Peers", ""]
    for name, info in peer_info.items():
        check = info["check"]
        lines.append(f"- {name}: pylinkage {info['pylinkage']}, numba {'yes' if info['numba'] else 'no'}, "
                     f"numpy {info['numpy']}, kinematics path `{info['path']}`"
                     + (f" (2000 steps: {info['path_times_2000_s']})" if info.get("path_times_2000_s") else "")
                     + f"; largest difference to ours over the N positions of A, B, E: positions "
                     f"{check['positions']:.2g} m, first analogs {check['first']:.2g} m/rad, second "
                     f"{check['second']:.2g} m/rad^2; compile/check time {info['warmup_s']:.1f} s")
    for key, reason in notes.items():
        lines.append(f"- note ({key}): {reason}")
    if extra.get("variants_assembled") is not None:
        lines.append(f"- variants: {extra['variants_assembled']:.1%} of the position-variants assembled")
    lines += ["", "## Profile notes for the missed goals", "",
              ("One short paragraph per missed goal, written by hand from the cProfile output "
              "(`python benchmarks/run.py --quick --profile`). The text between the markers is kept when "
              "this file is regenerated."), ""]
    old = _notes_blocks(extra.get("old_text", ""))
    for g in GOALS:
        if goals[g.key]["met"] is False or g.key in old:
            body = old.get(g.key, "_(profile paragraph to be written)_\n")
            lines += [f"### {g.text}", "", f"<!-- notes:{g.key} -->", body.rstrip("\n"), f"<!-- /notes:{g.key} -->",
                      ""]
    if extra.get("profile"):
        lines += ["## cProfile", "", *extra["profile"]]
    if extra.get("trade"):
        lines += ["", *extra["trade"]]
    return lines


# ----------------------------------------------------------------------------------------------
# main
# ----------------------------------------------------------------------------------------------


def variants_assembled() -> float | None:
    analyze_variants = getattr(linkage, "analyze_variants", None)
    if analyze_variants is None:
        return None
    four = linkage.load(FOURBAR)
    geometry = variant_geometry(four, VARIANTS, VARIANT_SEED, VARIANT_SPREAD)
    phi12 = np.linspace(0.0, 2.0 * np.pi, SMALL_N, endpoint=False)
    try:
        return float(np.mean(analyze_variants(four, phi12, geometry, order=2, on_failure="mask").status == 0))
    except Exception:  # noqa: BLE001 - the contender's own failure is reported already
        return None


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description="Speed of the library against pylinkage, a hand-fused kernel "
                                     "and its goals; writes RESULTS.md and prints one JSON line last.")
    parser.add_argument("--quick", action="store_true", help="N = 1e5 and 5 rounds (under 3 min on 2 cores)")
    parser.add_argument("--out", type=Path, default=BENCH_DIR / "RESULTS.md", help="the markdown file to write")
    parser.add_argument("--profile", action="store_true",
                        help="cProfile our four-bar full kinematics at N and N = 12 into the markdown")
    parser.add_argument("--rounds", type=int, help="paired rounds (default 5 quick, 7 full)")
    parser.add_argument("--positions", type=int, help="N (default 1e5 quick, 1e6 full)")
    parser.add_argument("--no-peers", action="store_true", help="leave pylinkage out (no venvs)")
    parser.add_argument("--memory-probe", type=int, help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.memory_probe:
        print(json.dumps(memory_probe(args.memory_probe)))
        return 0
    t_start = time.perf_counter()
    settings = settings_for(args.quick, args.rounds, args.positions)
    command = "python benchmarks/run.py" + (" " + " ".join(sys.argv[1:]) if len(sys.argv) > 1 else "")
    env = peers.subprocess_env()
    notes: dict[str, str] = {}
    peer_info: dict[str, dict] = {}
    probe = start_memory_probe(env)
    jobs = {} if args.no_peers else {name: peers.start_venv(name, env=env) for name in peers.PEER_VENVS}
    if args.no_peers:
        notes["pylinkage"] = "--no-peers"
    with tempfile.TemporaryDirectory(prefix="linkage_bench_") as tmp:
        reference = Path(tmp) / "reference.npz"
        write_reference(reference, settings.positions)
        workers = start_peers(settings, reference, env, notes, jobs)
        progress("warming up our contenders")
        ours = warm(our_contenders(settings, notes), notes)
        workers = wait_peers(workers, notes, peer_info)
        memory = finish_memory_probe(probe, notes)
        contenders = ours + peer_contenders(workers, settings.positions)
        progress(f"{settings.rounds} paired rounds of {len(contenders)} contenders, N = {settings.positions:,}")
        try:
            paired_rounds(contenders, settings.rounds, notes)
        finally:
            for worker in workers.values():
                worker.close()
    by_key = {c.key: c for c in contenders}
    figs = figures(by_key, memory, peer_info)
    goals = {g.key: goal_status(g, figs.get(g.key)) for g in GOALS}
    extra = {"variants_assembled": variants_assembled() if "variants_kinematics" in by_key else None,
             "old_text": args.out.read_text() if args.out.is_file() else ""}
    if args.profile:
        progress("cProfile")
        extra["profile"] = profile_lines(settings.positions)
    extra["trade"] = trade_lines(settings, env, notes)
    wall = time.perf_counter() - t_start
    _missing_reasons(figs, notes)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(results_markdown(settings, command, wall, figs, goals, peer_info, notes,
                                                   by_key, extra)) + "\n")
    progress(f"wrote {args.out} in {wall:.0f} s")
    for key, reason in notes.items():
        print(f"[bench] note ({key}): {reason}", file=sys.stderr)
    summary = {**figs, "goals": goals, "n_positions": settings.positions, "rounds": settings.rounds,
               "quick": settings.quick, "wall_s": wall, "memory_method": "tracemalloc peak over the call",
               "notes": notes}
    print(json.dumps(_finite(summary), allow_nan=False))
    return 0


def _finite(obj):
    """``obj`` with every non-finite float replaced by None (JSON has no NaN or inf)."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def _missing_reasons(figs: dict, notes: dict) -> None:
    """A reason for every null figure: a peer's figures and ratios take the reason that peer is missing."""
    for key, value in figs.items():
        if value is None and key not in notes:
            owner = next((name for name in peers.PEER_VENVS if name in key), None)
            reason = owner and (notes.get(owner) or notes.get("pylinkage"))
            notes[key] = f"{owner} did not run: {reason}" if reason else "not measured (see the notes above)"


if __name__ == "__main__":
    sys.exit(main())
