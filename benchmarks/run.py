"""The library's speed against its peers and its goals, in one command.

Run from the repository root::

    python benchmarks/run.py --quick      # N = 12, 360, 1e4, 1e5; 5 paired rounds: about 3 min on 2 cores
    python benchmarks/run.py              # and N = 1e6; 7 paired rounds: about 10 min
    python benchmarks/run.py --quick --profile   # and cProfile of our four-bar into RESULTS.md
    python benchmarks/run.py --quick --suite-seconds 412   # the test suite's wall time, for RESULTS.md

It writes ``benchmarks/RESULTS.md`` (``--out PATH``) and prints as its last stdout line one JSON
object with every figure (null where it cannot be measured; the reason goes to stderr), and one
progress line per stage on stderr.

How it measures: one thread for every numeric library (``OMP_NUM_THREADS=1`` set before numpy is
imported, and for every subprocess). Each contender (ours, the hand-fused kernel, pylinkage 1.3.0
with and without numba) runs at every N of :data:`SIZES` (and at ``--positions``). Every
contender runs once per *paired round*; the contenders of one N run one after the other, in an
order rotated by one each round, so the noise of a shared machine hits them alike. At small N a
run is many calls timed together and divided (one call at N = 12 takes 0.01-1 ms; the number of
calls is set once, after a warm-up, so that a run takes about ``round_seconds``). A figure is the
median over rounds; a ratio is computed within each round and then medianed. The peers (in venvs
created under ``benchmarks/.venvs/`` on first use) run in long-lived worker processes
(``peer_worker.py``) that time one run per request. The peak memory is measured in a fresh
subprocess with ``tracemalloc`` (numpy's allocations are traced by it); the Newton sweep in fresh
subprocesses, this tree's against :data:`BASELINE_COMMIT`'s (extracted with ``git archive``).

To time a new path of ours, change the one line in :func:`ours_kinematics` (and
:func:`ours_positions`): every figure of ours goes through them.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"
# ours at its best: with the fast extra (numba) installed, a kernel is compiled at its first call
# (in the warm-up) instead of after its numpy version has run a few seconds
os.environ.setdefault("LINKAGE_NUMBA", "1")

import argparse
import cProfile
import datetime
import importlib.metadata
import io
import json
import math
import platform
import pstats
import re
import resource
import statistics
import subprocess
import sys
import tarfile
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
from machine import cpu_model

import linkage
from linkage.kinetostatics.reactions import solve_reactions

#: the command the README gives (tests/test_benchmarks_contract.py holds the two to the same words)
README_COMMAND = "python benchmarks/run.py --quick"
#: the numbers of positions every ratio of the JSON line is measured at
SIZES = (12, 360, 10_000, 100_000)
FOURBAR = "four_bar"
SHAPER = "slotted_link_two_dyad"
NEWTON_SCHEME = "cylinder_boom"                      # one Newton-solved group: loading it is a traced sweep
#: the tree the Newton sweep is compared with: HEAD when the work on issue 24 (speed) began
BASELINE_COMMIT = "942ef0b8e137ec52f7a25fdec42e36906647b8ec"
POINTS = ("A", "B", "E")
MEMORY_N = 1_000_000
VARIANTS, VARIANT_POSITIONS, VARIANT_SEED, VARIANT_SPREAD = 10_000, 12, 20240601, 0.2
MAX_CALLS = 5000
DEFAULT_SHAPER_SPEED = 10.0                          # rad/s, when the scheme declares no mean speed
SUITE_ENV = "LINKAGE_SUITE_SECONDS"


@dataclass(frozen=True)
class Settings:
    """What one run measures and how long it may take."""

    quick: bool
    positions: int                                   # the main N: shaper, variants' peers, legacy keys
    rounds: int
    trade_timeout: float
    round_seconds: float                             # a run at small N: about this long (many calls)
    newton_rounds: int
    venv_timeout: float = 150.0

    @property
    def sizes(self) -> tuple[int, ...]:
        """Every N measured: :data:`SIZES` and the main N."""
        return tuple(sorted(set(SIZES) | {self.positions}))


def settings_for(quick: bool, rounds: int | None = None, positions: int | None = None) -> Settings:
    base = Settings(True, 100_000, 5, 150.0, 0.04, 3) if quick else Settings(False, 1_000_000, 7, 600.0, 0.15, 5)
    return Settings(base.quick, positions or base.positions, rounds or base.rounds, base.trade_timeout,
                    base.round_seconds, base.newton_rounds)


def progress(message: str) -> None:
    print(f"[bench] {message}", file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------
# the work that is timed
# ----------------------------------------------------------------------------------------------


def ours_kinematics(mech: linkage.Mechanism, phi: np.ndarray) -> tuple[linkage.Motion, dict]:
    """Our full kinematics of the four-bar: the Motion and A, B, E with their analogs.

    The one place our kinematics is called from (the rounds, the peers' reference, the memory
    probe, the profile): switch the line below to time a faster path.

    Returns
    -------
    motion, points
        ``points[P] = (position, first, second)``, each (N, 2), m, m/rad, m/rad^2.
    """
    motion = linkage.analyze(mech, phi, order=2, on_failure="mask")
    return motion, {p: (motion.point(p), *motion.point_analogs(p)) for p in POINTS}


def ours_positions(mech: linkage.Mechanism, phi: np.ndarray) -> dict:
    """Our positions of A, B, E, each (N, 2), m (order 0); the one place they are called from."""
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


def crank_angles(n: int) -> np.ndarray:
    """phi = 2 pi k / n, k = 0..n-1, rad (the grid pylinkage steps through)."""
    return np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)


# ----------------------------------------------------------------------------------------------
# contenders and paired rounds
# ----------------------------------------------------------------------------------------------


@dataclass
class Contender:
    """One timed thing: ``run(calls)`` does it ``calls`` times and returns the mean duration of one, s.

    ``block`` groups the contenders that run one after the other in a round (those of one N);
    ``times`` holds one mean duration per round, s.
    """

    key: str
    label: str
    positions: int
    run: Callable[[int], float]
    block: str = ""
    calls: int = 1
    times: list[float] = field(default_factory=list)

    def seconds(self) -> float | None:
        """Median duration of one call over the rounds, s."""
        return statistics.median(self.times) if self.times else None

    def rate(self) -> float | None:
        """Median positions per second over the rounds."""
        return self.positions / statistics.median(self.times) if self.times else None


def repeated(fn: Callable[[], object]) -> Callable[[int], float]:
    """``run(calls)``: ``fn`` called ``calls`` times, timed together; the mean per call, s."""
    def run(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        return (time.perf_counter() - t0) / calls
    return run


def key_at(base: str, n: int) -> str:
    """A contender's or figure's key at ``n`` positions: ``fourbar_kinematics_n360``."""
    return f"{base}_n{n}"


def fourbar_contenders(n: int, four: linkage.Mechanism) -> list[Contender]:
    """Ours (full kinematics, positions only) and the hand-fused kernel at ``n`` positions."""
    phi = crank_angles(n)
    geo = fourbar_geometry(four)
    block = f"N = {n:,}"
    return [
        Contender(key_at("fourbar_kinematics", n), f"ours, full kinematics, N = {n:,}", n,
                  repeated(lambda: ours_kinematics(four, phi)), block),
        Contender(key_at("fourbar_positions", n), f"ours, positions only, N = {n:,}", n,
                  repeated(lambda: ours_positions(four, phi)), block),
        Contender(key_at("handfused_kinematics", n), f"hand-fused numpy, full kinematics, N = {n:,}", n,
                  repeated(lambda: handfused.fourbar_kinematics(phi, **geo)), block),
        Contender(key_at("handfused_positions", n), f"hand-fused numpy, positions only, N = {n:,}", n,
                  repeated(lambda: handfused.fourbar_positions(phi, **geo)), block),
    ]


def our_contenders(settings: Settings, notes: dict) -> list[Contender]:
    """The four-bar at every N, the shaper at the main N and the variants."""
    n = settings.positions
    four = linkage.load(FOURBAR)
    out = [c for size in settings.sizes for c in fourbar_contenders(size, four)]
    shaper = linkage.load(SHAPER)
    omega, source = shaper_speed(shaper)
    notes["shaper_speed"] = source
    phi = crank_angles(n)
    out.append(Contender("shaper_reactions", f"ours, shaper kinematics + reactions, N = {n:,}", n,
                         repeated(lambda: shaper_reactions(shaper, phi, omega)), "other"))
    analyze_variants = getattr(linkage, "analyze_variants", None)
    if analyze_variants is None:
        notes["variants_kinematics_per_s"] = "linkage.analyze_variants does not exist (yet)"
    else:
        geometry = variant_geometry(four, VARIANTS, VARIANT_SEED, VARIANT_SPREAD)
        phi12 = crank_angles(VARIANT_POSITIONS)
        out.append(Contender("variants_kinematics", "ours, 10 000 four-bar variants x 12 positions, one call",
                             VARIANTS * VARIANT_POSITIONS,
                             repeated(lambda: analyze_variants(four, phi12, geometry, order=2, on_failure="mask")),
                             "other"))
    return out


def calls_per_run(run: Callable[[int], float], round_seconds: float) -> int:
    """The calls that make a run of about ``round_seconds`` (at least 1, at most :data:`MAX_CALLS`):
    runs of 1, 4, 16 ... calls until one lasts a quarter of that, so a slow first call or a busy
    moment of the machine does not set the count."""
    calls = 1
    while True:
        per_call = max(run(calls), 1e-9)
        if per_call * calls >= round_seconds / 4 or calls >= MAX_CALLS:
            return int(min(MAX_CALLS, max(1, math.ceil(round_seconds / per_call))))
        calls *= 4


def warm_and_calibrate(contenders: list[Contender], round_seconds: float, notes: dict) -> list[Contender]:
    """Run each contender once untimed (warm-up), then set its calls per run (:func:`calls_per_run`);
    one that fails is dropped with the reason in ``notes``."""
    kept = []
    for c in contenders:
        try:
            first = c.run(1)
            c.calls = 1 if first >= round_seconds else calls_per_run(c.run, round_seconds)
        except Exception as exc:  # noqa: BLE001 - any failure of a contender is reported, not fatal
            notes[c.key] = f"{c.label} failed: {type(exc).__name__}: {exc}"
            continue
        kept.append(c)
    return kept


def blocks_of(contenders: list[Contender]) -> list[list[Contender]]:
    """The contenders grouped by ``block``, in the order of their first appearance."""
    blocks: dict[str, list[Contender]] = {}
    for c in contenders:
        blocks.setdefault(c.block, []).append(c)
    return list(blocks.values())


def paired_rounds(contenders: list[Contender], rounds: int, notes: dict) -> None:
    """Each round runs every contender once, block after block; within a block the order is
    rotated by one each round. A contender that fails in any round loses its figure."""
    t0 = time.perf_counter()
    for r in range(rounds):
        for block in blocks_of(contenders):
            k = r % len(block)
            for c in block[k:] + block[:k]:
                try:
                    c.times.append(c.run(c.calls))
                except Exception as exc:  # noqa: BLE001 - a peer that dies mid-run loses its figure
                    notes[c.key] = f"{c.label} failed in round {r + 1}: {exc}"
                    c.times.append(float("nan"))
        progress(f"round {r + 1}/{rounds} done ({time.perf_counter() - t0:.0f} s)")
    for c in contenders:
        if any(not np.isfinite(t) for t in c.times):
            c.times = []


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
    phi = crank_angles(n)
    _, points = ours_kinematics(linkage.load(FOURBAR), phi)
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


def peer_contenders(workers: dict, sizes: tuple[int, ...]) -> list[Contender]:
    out = []
    for n in sizes:
        for name, worker in workers.items():
            for task, key, label in PEER_TASKS[name]:
                out.append(Contender(key_at(key, n), f"{label}, N = {n:,}", n,
                                     lambda calls, w=worker, t=task, n=n: w.seconds(t, n, calls), f"N = {n:,}"))
    return out


def start_peers(settings: Settings, references: list[Path], env: dict, notes: dict, jobs: dict) -> dict:
    """Wait for the venvs, start one worker per peer; those that fail are left out with the reason."""
    workers = {}
    for name, job in jobs.items():
        try:
            python = peers.finish_venv(job, settings.venv_timeout)
            workers[name] = peers.PeerWorker(python, references, env)
        except peers.PeerUnavailable as exc:
            notes[name] = str(exc)
    return workers


def wait_peers(workers: dict, notes: dict, info: dict) -> dict:
    ready = {}
    for name, worker in workers.items():
        try:
            info[name] = worker.wait_ready(timeout=900.0)
            ready[name] = worker
            worst = max(check["positions"] for check in info[name]["check"].values())
            progress(f"{name}: ready ({info[name]['path']} path, largest difference to ours over every N: "
                     f"{worst:.2g} m)")
        except peers.PeerUnavailable as exc:
            notes[name] = str(exc)
    return ready


# ----------------------------------------------------------------------------------------------
# memory and the Newton sweep (fresh subprocesses), profile
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
    ours_kinematics(mech, np.linspace(0.0, 1.0, 16))              # caches and lazy imports
    phi = crank_angles(n)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    motion, points = ours_kinematics(mech, phi)
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


_NEWTON_CHILD = """
import json, sys, time
sys.path.insert(0, sys.argv[1])
import linkage
assert linkage.__file__.startswith(sys.argv[1]), linkage.__file__
linkage.load("four_bar")                             # lazy imports, outside the timing
t0 = time.perf_counter()
linkage.load(sys.argv[2])
print(json.dumps({"load_s": time.perf_counter() - t0}))
"""


def newton_load_seconds(root: Path, env: dict) -> float:
    """Seconds ``linkage.load(NEWTON_SCHEME)`` takes in a fresh process on the tree at ``root``."""
    done = subprocess.run([sys.executable, "-c", _NEWTON_CHILD, str(root), NEWTON_SCHEME], capture_output=True,
                          text=True, timeout=600, env=env, cwd=str(root), check=False)
    if done.returncode != 0:
        raise RuntimeError(" | ".join(done.stderr.strip().splitlines()[-2:]))
    return float(json.loads(done.stdout.strip().splitlines()[-1])["load_s"])


def newton_sweep(rounds: int, commit: str, env: dict, notes: dict) -> dict | None:
    """Loading :data:`NEWTON_SCHEME` (its one Newton-solved group traced over the stroke) here and
    on the tree of ``commit``, alternating, ``rounds`` times each in fresh processes: the median
    times (s) and the median of the per-round ratio baseline / ours."""
    with tempfile.TemporaryDirectory(prefix="linkage_baseline_") as tmp:
        try:
            tar = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", commit, "assur", "linkage",
                                  "schemes"], capture_output=True, check=True, timeout=120).stdout
            with tarfile.open(fileobj=io.BytesIO(tar)) as archive:
                archive.extractall(tmp, filter="data")
        except (OSError, subprocess.SubprocessError, tarfile.TarError) as exc:
            notes["newton_sweep_speedup"] = f"the tree of commit {commit} could not be extracted: {exc}"
            return None
        ours, base = [], []
        try:
            for r in range(rounds):
                pair = [(ours, REPO), (base, Path(tmp))]
                for times, root in pair[r % 2:] + pair[:r % 2]:
                    times.append(newton_load_seconds(root, env))
        except (RuntimeError, subprocess.SubprocessError, ValueError) as exc:
            notes["newton_sweep_speedup"] = f"loading {NEWTON_SCHEME} failed: {exc}"
            return None
    return {"ours_s": statistics.median(ours), "baseline_s": statistics.median(base),
            "speedup": statistics.median(b / o for b, o in zip(base, ours)), "commit": commit}


def profile_lines(positions: int) -> list[str]:
    """cProfile of our full kinematics of the four-bar at N = ``positions`` and N = 12, top 15 cumulative."""
    mech = linkage.load(FOURBAR)
    lines = []
    for n, calls in ((positions, 1), (12, 200)):
        phi = crank_angles(n)
        ours_kinematics(mech, phi)
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(calls):
            ours_kinematics(mech, phi)
        profiler.disable()
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).strip_dirs().sort_stats("cumulative").print_stats(15)
        body = text.getvalue().strip().splitlines()
        start = next((i for i, line in enumerate(body) if line.lstrip().startswith("ncalls")), 0)
        lines += [f"### cProfile: four-bar full kinematics, N = {n}, {calls} call(s), top 15 by cumulative time",
                  "", "```", *[line.rstrip() for line in body[max(0, start - 2):]], "```", ""]
    return lines


# ----------------------------------------------------------------------------------------------
# trade.py (another benchmark, appended)
# ----------------------------------------------------------------------------------------------

_TRADE_CHILD = """
import json, sys
sys.path.insert(0, sys.argv[1])
import trade
print(json.dumps([str(line) for line in trade.run(sys.argv[2] == "quick", images=None)]))
"""


def trade_lines(settings: Settings, env: dict, notes: dict) -> list[str]:
    """Lines of ``benchmarks/trade.py``'s ``run(quick)``, run in a subprocess time-boxed to the settings."""
    progress(f"benchmarks/trade.py (at most {settings.trade_timeout:.0f} s)")
    try:
        done = subprocess.run([sys.executable, "-c", _TRADE_CHILD, str(BENCH_DIR), "quick" if settings.quick else "full"],
                              check=False, capture_output=True, text=True, timeout=settings.trade_timeout, env=env,
                              cwd=str(REPO))
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
    """One row of the goals table: figure ``key`` against ``target`` (``at_least`` or at most).

    ``family`` names the goal of the issue the row belongs to (one row per goal per N); the
    hand-written profile paragraph of a missed goal is kept under it.
    """

    key: str
    family: str
    text: str
    target: float
    at_least: bool
    unit: str = ""

    @property
    def id(self) -> str:
        return f"{self.key}{'>=' if self.at_least else '<='}{self.target:g}"


def goals_for(sizes: tuple[int, ...]) -> tuple[Goal, ...]:
    """The goals of issue 24, one row per goal per N of ``sizes`` where it applies."""
    out = []
    for n in sizes:
        out.append(Goal(key_at("kinematics_vs_pylinkage_numba", n), "kinematics_vs_pylinkage_numba",
                        f"full kinematics >= 1x pylinkage + numba, N = {n:,}", 1.0, True, "x"))
    for n in sizes:
        if n >= 10_000:
            out.append(Goal(key_at("kinematics_vs_pylinkage_numba", n), "kinematics_vs_pylinkage_numba",
                            f"full kinematics >= 2x pylinkage + numba, N = {n:,}", 2.0, True, "x"))
    for n in sizes:
        if n >= 10_000:
            out.append(Goal(key_at("handfused_over_ours_kinematics", n), "handfused_over_ours_kinematics",
                            f"full kinematics >= 1/1.5 of the hand-fused kernel (hand-fused / ours <= 1.5), "
                            f"N = {n:,}", 1.5, False, "x"))
    for n in sizes:
        if n >= 360:
            out.append(Goal(key_at("positions_vs_pylinkage_numba", n), "positions_vs_pylinkage_numba",
                            f"positions only >= 1x pylinkage + numba, N = {n:,}", 1.0, True, "x"))
    out += [
        Goal("fourbar_call_n12_s", "fourbar_call_n12_s", "one full-kinematics call at N = 12 <= 0.04 ms", 4e-5,
             False, "s"),
        Goal("variants_kinematics_per_s", "variants_kinematics_per_s", "variant batches >= 5 M position-variants/s",
             5e6, True, "position-variants/s"),
        Goal("shaper_reactions_per_s", "shaper_reactions_per_s", "shaper kinematics + reactions >= 1 M positions/s",
             1e6, True, "positions/s"),
        Goal("newton_sweep_speedup", "newton_sweep_speedup",
             f"Newton sweep >= 5x faster (loading {NEWTON_SCHEME}, a traced Newton sweep, against commit "
             f"{BASELINE_COMMIT[:7]})", 5.0, True, "x"),
        Goal("peak_memory_over_result", "peak_memory_over_result", "peak memory at 1e6 positions <= 2x the result",
             2.0, False, "x"),
    ]
    return tuple(out)


def goal_status(goal: Goal, value: float | None) -> dict:
    """Met or not, and the factor by which a missed goal is missed (>= 1)."""
    if value is None or not np.isfinite(value):
        return {"figure": goal.key, "value": None, "goal": goal.text, "met": None, "missed_by_factor": None}
    met = value >= goal.target if goal.at_least else value <= goal.target
    factor = (goal.target / value if goal.at_least else value / goal.target) if value > 0 else float("inf")
    return {"figure": goal.key, "value": value, "goal": goal.text, "met": bool(met),
            "missed_by_factor": None if met else factor}


#: contender bases timed at every N (per-call seconds in the JSON line's ``per_call_s``)
FOURBAR_BASES = ("fourbar_kinematics", "fourbar_positions", "handfused_kinematics", "handfused_positions",
                 "pylinkage_numba_kinematics", "pylinkage_numba_positions", "pylinkage_numba_kinematics_points",
                 "pylinkage_plain_kinematics")
#: ratio key -> (faster, slower) contender bases, computed at every N
RATIOS = {
    "kinematics_vs_pylinkage_numba": ("fourbar_kinematics", "pylinkage_numba_kinematics"),
    "kinematics_vs_pylinkage_numba_points": ("fourbar_kinematics", "pylinkage_numba_kinematics_points"),
    "kinematics_vs_pylinkage_plain": ("fourbar_kinematics", "pylinkage_plain_kinematics"),
    "positions_vs_pylinkage_numba": ("fourbar_positions", "pylinkage_numba_positions"),
    "kinematics_vs_handfused": ("fourbar_kinematics", "handfused_kinematics"),
    "handfused_over_ours_kinematics": ("handfused_kinematics", "fourbar_kinematics"),
    "positions_vs_handfused": ("fourbar_positions", "handfused_positions"),
}


def summary(contenders: dict[str, Contender], sizes: tuple[int, ...], main_n: int, memory: dict | None = None,
            peer_info: dict | None = None, newton: dict | None = None) -> dict:
    """Every figure of the JSON line (floats or None) and the goals, from the rounds' timings.

    Per N of ``sizes``: every ratio of :data:`RATIOS` as ``<ratio>_n<N>`` and each contender's
    median seconds per call in ``per_call_s[<base>][<N>]``; at the main N ``main_n`` the same
    ratios without suffix and ``<base>_per_s`` (the keys of earlier runs); ``fourbar_call_n12_s``
    the median seconds of one full-kinematics call at N = 12.
    """
    c = contenders.get

    def rate(key):
        return c(key).rate() if c(key) else None

    out: dict = {}
    for base in FOURBAR_BASES:
        out[base + "_per_s"] = rate(key_at(base, main_n))
    out["shaper_reactions_per_s"] = rate("shaper_reactions")
    out["variants_kinematics_per_s"] = rate("variants_kinematics")
    n12 = c(key_at("fourbar_kinematics", 12))
    out["fourbar_call_n12_s"] = n12.seconds() if n12 else None
    for ratio, (faster, slower) in RATIOS.items():
        out[ratio] = paired_ratio(c(key_at(faster, main_n)), c(key_at(slower, main_n)))
        for n in sizes:
            out[key_at(ratio, n)] = paired_ratio(c(key_at(faster, n)), c(key_at(slower, n)))
    out["per_call_s"] = {base: {str(n): c(key_at(base, n)).seconds() if c(key_at(base, n)) else None for n in sizes}
                         for base in FOURBAR_BASES}
    peak = memory and memory.get("peak_tracemalloc_bytes")
    result = memory and memory.get("result_bytes")
    out["peak_memory_1e6_bytes"] = float(peak) if peak else None
    out["result_1e6_bytes"] = float(result) if result else None
    out["peak_memory_over_result"] = peak / result if peak and result else None
    out["maxrss_growth_1e6_bytes"] = float(memory["maxrss_growth_bytes"]) if memory else None
    out["newton_sweep_speedup"] = newton["speedup"] if newton else None
    out["newton_load_s"] = newton["ours_s"] if newton else None
    out["newton_load_baseline_s"] = newton["baseline_s"] if newton else None
    for name, info in (peer_info or {}).items():
        for what in ("positions", "first", "second"):
            worst = [check.get(what) for check in info["check"].values()]
            out[f"{name}_max_{what.replace('positions', 'position')}_difference_m"] = (
                max(worst) if worst and all(w is not None and np.isfinite(w) for w in worst) else None)
    out["goals"] = {g.id: goal_status(g, out.get(g.key)) for g in goals_for(sizes)}
    return out


# ----------------------------------------------------------------------------------------------
# RESULTS.md
# ----------------------------------------------------------------------------------------------


def machine() -> dict:
    """CPU model (/proc/cpuinfo "model name"), cores, and the versions of Python, numpy, numba."""
    model = cpu_model()
    try:
        numba = importlib.metadata.version("numba")
    except importlib.metadata.PackageNotFoundError:
        numba = "not installed"
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"cpu": model, "cores": os.cpu_count(), "usable_cores": usable, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba, "platform": platform.platform()}


def suite_seconds(option: float | None) -> float | None:
    """The test suite's wall time, s: ``--suite-seconds`` or the environment variable :data:`SUITE_ENV`."""
    if option is not None:
        return option
    try:
        return float(os.environ[SUITE_ENV])
    except (KeyError, ValueError):
        return None


def fmt(value: float | None, unit: str = "") -> str:
    if value is None:
        return "n/a"
    if unit == "s":
        return f"{value:.3g} s" if value >= 1 else f"{value * 1e3:.3g} ms"
    if unit == "bytes":
        return f"{value / 2**20:.1f} MiB"
    if unit == "x":
        return f"{value:.3g}x"
    return f"{value:,.0f}" if abs(value) >= 100 else f"{value:.3g}"


def _notes_blocks(old_text: str) -> dict[str, str]:
    """Hand-written profile paragraphs of a previous RESULTS.md, by goal family (kept across runs)."""
    pattern = re.compile(r"<!-- notes:(\w+) -->\n(.*?)<!-- /notes:\1 -->", re.DOTALL)
    return {m.group(1): m.group(2) for m in pattern.finditer(old_text)}


def goals_table(goals: tuple[Goal, ...], status: dict) -> list[str]:
    lines = ["| goal | figure | value | met? | by how much |", "|---|---|---|---|---|"]
    for g in goals:
        s = status[g.id]
        met = "n/a" if s["met"] is None else "yes" if s["met"] else "**no**"
        by = ""
        if s["met"] is False:
            by = (f"needs {s['missed_by_factor']:.3g}x more" if g.at_least
                  else f"{s['missed_by_factor']:.3g}x over the limit")
        elif s["met"]:
            margin = s["value"] / g.target if g.at_least else g.target / s["value"]
            by = f"{margin:.3g}x to spare"
        unit = "" if g.unit in ("s", "x") or s["value"] is None else " " + g.unit
        lines.append(f"| {g.text} | `{g.key}` | {fmt(s['value'], g.unit)}{unit} | {met} | {by} |")
    return lines


def per_n_tables(figs: dict, sizes: tuple[int, ...]) -> list[str]:
    """The per-call times and rates of every contender at every N, and the ratios at every N."""
    head = "| | " + " | ".join(f"N = {n:,}" for n in sizes) + " |"
    rule = "|---|" + "---|" * len(sizes)
    lines = ["Median time of one call and positions per second:", "", head, rule]
    for base in FOURBAR_BASES:
        cells = []
        for n in sizes:
            s = figs["per_call_s"][base][str(n)]
            cells.append("n/a" if s is None else f"{fmt(s, 's')} ({n / s:,.0f}/s)")
        lines.append(f"| `{base}` | " + " | ".join(cells) + " |")
    lines += ["", ("Ratios (within each round, then medianed; `X_vs_Y` is X's positions per second over Y's, "
                   "above 1: ours is faster):"), "", head, rule]
    for ratio in RATIOS:
        lines.append(f"| `{ratio}_nN` | " + " | ".join(fmt(figs.get(key_at(ratio, n)), "x") for n in sizes) + " |")
    return lines


SAME_WORK = """\
**Full kinematics of the four-bar** (`schemes/four_bar.toml`: O = (0, 0), C = (0.3, 0), OA = 0.1 m,
AB = 0.3 m, CB = 0.25 m, coupler point E 0.15 m from A at 30 deg CCW from AB, B on the left of the
directed line A -> C) at phi = 2 pi k / N, k = 0..N-1: the positions and the first and second
analogs (derivatives with respect to the crank angle; with omega = 1 rad/s and eps = 0 they are the
velocities and accelerations) of every link's angle and of the points A, B and E. Ours:
`ours_kinematics` in run.py, today `linkage.analyze(m, phi, order=2, on_failure="mask")`, then
`point(p)` and `point_analogs(p)` for p in A, B, E (the link angles and their analogs are in the
Motion's poses, first, second).
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
the "plain" venv is simply one without numba. pylinkage picks the circle intersection nearest to
the previous step's B (a marching simulation); ours and the hand-fused kernel compute each
position independently from the assembly rule.
**One call at N = 12**: the N = 12 run of our full kinematics, many calls timed together, divided.
**Shaper**: `slotted_link_two_dyad` (crank + RPR + PRP), `analyze(order=2, omega=w)` then
`solve_reactions` (gravity, inertia forces and moments, declared loads), at the main N.
**Variants**: one call of `linkage.analyze_variants` for 10 000 four-bars (OA, AB, CB and the
frame's C each scaled by a factor uniform in [0.8, 1.2], seed fixed; every point of a link scales
with it) at 12 positions; positions that cannot be assembled count too.
**Newton sweep**: `linkage.load("cylinder_boom")` (its one group is solved by Newton's method and
traced over the cylinder's stroke when the scheme is loaded) in a fresh process, this tree against
the tree of the baseline commit (`git archive`), alternating; the ratio is baseline / ours.
**Peak memory**: in a fresh subprocess, tracemalloc's peak over one full-kinematics call at
N = 1e6 (numpy reports its allocations to tracemalloc), against the sum of nbytes of the
result's arrays (the Motion's poses, first, second, status, conditioning, error bound, and the
A, B, E arrays with their analogs)."""


def results_markdown(settings: Settings, command: str, wall: float, figs: dict, peer_info: dict, notes: dict,
                     contenders: dict, extra: dict) -> list[str]:
    m = machine()
    suite = extra.get("suite_seconds")
    goals = goals_for(settings.sizes)
    lines = ["# Benchmarks: speed against peers and goals", "",
             f"- date: {datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}",
             f"- machine: CPU {m['cpu']}, {m['cores']} cores ({m['usable_cores']} usable); {m['platform']}",
             (f"- Python {m['python']}, numpy {m['numpy']}, numba {m['numba']} (this process); OMP_NUM_THREADS=1 "
              "(and every BLAS/numba thread count 1, for the subprocesses too)"),
             (f"- command: `{command}` ({'quick' if settings.quick else 'full'}: N = "
              f"{', '.join(f'{n:,}' for n in settings.sizes)}, {settings.rounds} paired rounds, main N "
              f"{settings.positions:,}; wall time {wall:.0f} s)"),
             f"- test suite wall time: {'not measured' if suite is None else f'{suite:.0f} s'}",
             ("- the machine may have been shared while this ran: the ratios (within paired rounds) are "
              "more trustworthy than the absolute figures"), "",
             "## Goals", "", *goals_table(goals, figs["goals"]), "",
             "## Every N", "", *per_n_tables(figs, settings.sizes), "",
             "## Other figures", "", "| figure | value |", "|---|---|"]
    for key, label, unit in (
            ("shaper_reactions_per_s", "ours, shaper kinematics + reactions (inertia), main N", "positions/s"),
            ("variants_kinematics_per_s", "ours, 10 000 variants x 12 positions in one call", "position-variants/s"),
            ("fourbar_call_n12_s", "ours, one full-kinematics call at N = 12", "s"),
            ("newton_load_s", f"ours, loading {NEWTON_SCHEME} (fresh process)", "s"),
            ("newton_load_baseline_s", f"commit {BASELINE_COMMIT[:7]}, loading {NEWTON_SCHEME}", "s"),
            ("peak_memory_1e6_bytes", "ours, peak memory of full kinematics at N = 1e6 (tracemalloc)", "bytes"),
            ("maxrss_growth_1e6_bytes", "ours, growth of the peak RSS over that call (ru_maxrss)", "bytes"),
            ("result_1e6_bytes", "the result's arrays at N = 1e6", "bytes")):
        shown = fmt(figs.get(key), unit if unit in ("s", "bytes") else "")
        lines.append(f"| {label} (`{key}`) | {shown}{'' if unit in ('s', 'bytes') else ' ' + unit} |")
    lines += ["", "Per-round times (s per call; calls per run in brackets):", "", "| contender | times per round |",
              "|---|---|"]
    for c in contenders.values():
        lines.append(f"| {c.label} ({c.calls}) | {', '.join(f'{t:.4g}' for t in c.times) or 'n/a'} |")
    lines += ["", "## Same work", "", SAME_WORK, "", "## How the rounds are paired", "",
              ("Every contender, ours in this process and each peer in its own long-lived worker process, runs "
               "once per round; the contenders of one N run one after the other, their order rotated by one "
               "from one round to the next, so each takes every slot once and a slow spell of the shared "
               "machine hits all of them. At small N a run is many calls timed together (the count is set "
               "after a warm-up so that a run takes about "
               f"{settings.round_seconds * 1e3:.0f} ms) and the figure is the time per call. A peer's run is "
               "requested by this process and timed inside the worker (no start-up, import or compile time: "
               "the worker compiles and checks before the rounds). A ratio pairs the two contenders' runs of "
               "the same round; the figure is the median over rounds."), "", "## Peers", ""]
    for name, info in peer_info.items():
        worst = {what: max(check[what] for check in info["check"].values()) for what in ("positions", "first",
                                                                                         "second")}
        lines.append(f"- {name}: pylinkage {info['pylinkage']}, numba {info.get('numba_version') or 'no'}, "
                     f"numpy {info['numpy']}, kinematics path `{info['path']}`"
                     + (f" (2000 steps: {info['path_times_2000_s']})" if info.get("path_times_2000_s") else "")
                     + f"; largest difference to ours over every N of A, B, E: positions {worst['positions']:.2g} m, "
                     f"first analogs {worst['first']:.2g} m/rad, second {worst['second']:.2g} m/rad^2; "
                     f"compile/check time {info['warmup_s']:.1f} s")
    for key, reason in notes.items():
        lines.append(f"- note ({key}): {reason}")
    if extra.get("variants_assembled") is not None:
        lines.append(f"- variants: {extra['variants_assembled']:.1%} of the position-variants assembled")
    lines += ["", "## Profile notes for the missed goals", "",
              ("One short paragraph per missed goal, written by hand from the cProfile output "
               "(`python benchmarks/run.py --quick --profile`). The text between the markers is kept when "
               "this file is regenerated."), ""]
    old = _notes_blocks(extra.get("old_text", ""))
    families = dict.fromkeys(g.family for g in goals)
    for family in families:
        mine = [g for g in goals if g.family == family]
        missed = [g.text for g in mine if figs["goals"][g.id]["met"] is False]
        if missed or family in old:
            body = old.get(family, "_(profile paragraph to be written)_\n")
            title = " / ".join(dict.fromkeys(text.split(", N = ")[0] for text in missed or [mine[0].text]))
            at = [text.split(", N = ")[1] for text in missed if ", N = " in text]
            title += f" (missed at N = {', '.join(dict.fromkeys(at))})" if at else "" if missed else " (met)"
            lines += [f"### {title}", "", f"<!-- notes:{family} -->", body.rstrip("\n"), f"<!-- /notes:{family} -->",
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
    try:
        motion = analyze_variants(four, crank_angles(VARIANT_POSITIONS), geometry, order=2, on_failure="mask")
        return float(np.mean(motion.status == 0))
    except Exception:  # noqa: BLE001 - the contender's own failure is reported already
        return None


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description="Speed of the library against pylinkage, a hand-fused kernel "
                                     "and its goals; writes RESULTS.md and prints one JSON line last.")
    parser.add_argument("--quick", action="store_true",
                        help="5 rounds, main N = 1e5 (N = 12, 360, 1e4, 1e5; about 3 min on 2 cores)")
    parser.add_argument("--out", type=Path, default=BENCH_DIR / "RESULTS.md", help="the markdown file to write")
    parser.add_argument("--profile", action="store_true",
                        help="cProfile our four-bar full kinematics at the main N and N = 12 into the markdown")
    parser.add_argument("--rounds", type=int, help="paired rounds (default 5 quick, 7 full)")
    parser.add_argument("--positions", type=int, help="the main N, measured besides 12, 360, 1e4, 1e5 "
                        "(default 1e5 quick, 1e6 full)")
    parser.add_argument("--no-peers", action="store_true", help="leave pylinkage out (no venvs)")
    parser.add_argument("--no-trade", action="store_true", help="leave benchmarks/trade.py out")
    parser.add_argument("--suite-seconds", type=float,
                        help=f"the test suite's wall time, s, for RESULTS.md (default: ${SUITE_ENV}, else "
                        "'not measured')")
    parser.add_argument("--baseline", default=BASELINE_COMMIT, help="the commit the Newton sweep is compared with")
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
    progress(f"N = {', '.join(f'{n:,}' for n in settings.sizes)}; {settings.rounds} paired rounds")
    probe = start_memory_probe(env)
    jobs = {} if args.no_peers else {name: peers.start_venv(name, env=env) for name in peers.PEER_VENVS}
    if args.no_peers:
        notes["pylinkage"] = "--no-peers"
    with tempfile.TemporaryDirectory(prefix="linkage_bench_") as tmp:
        progress("our reference results for the peers' check")
        references = []
        for n in settings.sizes:
            references.append(Path(tmp) / f"reference_n{n}.npz")
            write_reference(references[-1], n)
        if jobs:
            progress("peers: venvs (created on first use), workers started")
        workers = wait_peers(start_peers(settings, references, env, notes, jobs), notes, peer_info)
        progress("waiting for the memory probe (N = 1e6, fresh process)")
        memory = finish_memory_probe(probe, notes)
        progress("warming up our contenders and setting their calls per run")
        ours = warm_and_calibrate(our_contenders(settings, notes), settings.round_seconds, notes)
        progress("warming up the peers and setting their calls per run")
        theirs = warm_and_calibrate(peer_contenders(workers, settings.sizes), settings.round_seconds, notes)
        contenders = sorted(ours + theirs, key=lambda c: (c.block == "other", c.positions))
        progress(f"{settings.rounds} paired rounds of {len(contenders)} contenders")
        try:
            paired_rounds(contenders, settings.rounds, notes)
        finally:
            for worker in workers.values():
                worker.close()
    progress(f"Newton sweep: loading {NEWTON_SCHEME} here and at {args.baseline[:7]}, {settings.newton_rounds} "
             "rounds")
    newton = newton_sweep(settings.newton_rounds, args.baseline, env, notes)
    by_key = {c.key: c for c in contenders}
    figs = summary(by_key, settings.sizes, settings.positions, memory, peer_info, newton)
    extra = {"variants_assembled": variants_assembled() if "variants_kinematics" in by_key else None,
             "old_text": args.out.read_text() if args.out.is_file() else "",
             "suite_seconds": suite_seconds(args.suite_seconds)}
    if args.profile:
        progress("cProfile")
        extra["profile"] = profile_lines(settings.positions)
    extra["trade"] = [] if args.no_trade else trade_lines(settings, env, notes)
    wall = time.perf_counter() - t_start
    _missing_reasons(figs, notes)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(results_markdown(settings, command, wall, figs, peer_info, notes, by_key, extra))
                        + "\n")
    progress(f"wrote {args.out} in {wall:.0f} s")
    for key, reason in notes.items():
        print(f"[bench] note ({key}): {reason}", file=sys.stderr)
    m = machine()
    out = {**figs, "sizes": list(settings.sizes), "n_positions": settings.positions, "rounds": settings.rounds,
           "quick": settings.quick, "wall_s": wall, "suite_wall_s": extra["suite_seconds"], "cpu": m["cpu"],
           "python": m["python"], "numpy": m["numpy"], "numba": m["numba"],
           "memory_method": "tracemalloc peak over the call", "notes": notes}
    print(json.dumps(_finite(out), allow_nan=False))
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
    """A reason for every null figure: those of a peer that did not run share one note with its
    reason; any other gets its own."""
    by_peer: dict[str, list[str]] = {}
    for key, value in figs.items():
        if value is None and key not in notes:
            owner = next((name for name in peers.PEER_VENVS if name in key), None)
            if owner and (notes.get(owner) or notes.get("pylinkage")):
                by_peer.setdefault(owner, []).append(key)
            else:
                notes[key] = "not measured (see the notes above)"
    for owner, keys in by_peer.items():
        notes[owner + "_figures"] = (f"{len(keys)} figures are null ({keys[0]} ...): {owner} did not run: "
                                     f"{notes.get(owner) or notes.get('pylinkage')}")


if __name__ == "__main__":
    sys.exit(main())
