"""What ``benchmarks/run.py`` and ``benchmarks/trade.py`` promise, checked without running a benchmark.

1. run.py's summary (the figures of its last JSON line) has, for every N of 12, 360, 10 000 and
   100 000, the keys ``kinematics_vs_pylinkage_numba_nN``, ``positions_vs_pylinkage_numba_nN`` and
   ``handfused_over_ours_kinematics_nN``, each the median over rounds of the per-round ratio
   computed here from fake timings; ``fourbar_call_n12_s`` and the keys of earlier runs; one goal
   row per goal of issue 24 per N, met or missed by the factor computed here.
2. trade.py sweeps a slide input over its declared stroke (metres, the numbers of
   ``schemes/piston_driven_crank.toml``), its finite differences there follow the h^4 law of a
   5-point formula (so the step really is h x stroke / 2 pi m), and every shipped scheme gives
   finite figures.
3. The README's benchmark command is the one run.py documents, and run.py accepts it.
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import statistics
import sys
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

import linkage

ROOT = Path(__file__).resolve().parent.parent
SIZES = (12, 360, 10_000, 100_000)


def _load(name: str, path: Path):
    """A script of ``benchmarks/`` as a module (run.py sets thread variables: they are restored)."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up while the file runs
    with mock.patch.dict(os.environ):
        spec.loader.exec_module(module)
    return module


bench = _load("bench_run", ROOT / "benchmarks" / "run.py")
trade = _load("trade", ROOT / "benchmarks" / "trade.py")

# ----------------------------------------------------------------------------------------------
# 1. the summary's keys and values from fake timings
# ----------------------------------------------------------------------------------------------

#: seconds per call in each of 3 rounds, per contender base, at N (made up; ours slower at small N)
BASES = ("fourbar_kinematics", "fourbar_positions", "handfused_kinematics", "handfused_positions",
         "pylinkage_numba_kinematics", "pylinkage_numba_positions", "pylinkage_numba_kinematics_points",
         "pylinkage_plain_kinematics")


def fake_times(base: str, n: int) -> list[float]:
    """Per-call seconds of three rounds: a per-position cost per contender, a different noise per round."""
    per_position = {"fourbar_kinematics": 1.0e-6, "fourbar_positions": 0.5e-6, "handfused_kinematics": 0.2e-6,
                    "handfused_positions": 0.1e-6, "pylinkage_numba_kinematics": 0.8e-6,
                    "pylinkage_numba_positions": 0.3e-6, "pylinkage_numba_kinematics_points": 0.6e-6,
                    "pylinkage_plain_kinematics": 40e-6}[base]
    overhead = 5e-4 if base.startswith("fourbar") else 1e-5      # our call overhead dominates at N = 12
    noise = (1.0, 1.3, 0.9) if base.startswith("fourbar") else (1.1, 1.0, 1.2)
    return [(overhead + per_position * n) * k for k in noise]


@pytest.fixture(scope="module")
def contenders():
    out = {}
    for n in SIZES:
        for base in BASES:
            key = f"{base}_n{n}"
            out[key] = bench.Contender(key, key, n, lambda calls: 0.0, times=fake_times(base, n))
    out["shaper_reactions"] = bench.Contender("shaper_reactions", "", 100_000, lambda calls: 0.0,
                                              times=[0.5, 0.4, 0.6])
    out["variants_kinematics"] = bench.Contender("variants_kinematics", "", 120_000, lambda calls: 0.0,
                                                 times=[0.03, 0.02, 0.025])
    return out


@pytest.fixture(scope="module")
def figures(contenders):
    memory = {"peak_tracemalloc_bytes": 300.0, "result_bytes": 200.0, "maxrss_growth_bytes": 250.0}
    newton = {"speedup": 6.0, "ours_s": 0.2, "baseline_s": 1.2}
    return bench.summary(contenders, SIZES, 100_000, memory=memory, peer_info={}, newton=newton)


def ratio(faster: str, slower: str, n: int) -> float:
    """The median over rounds of faster's positions/s over slower's (same N: slower's time / faster's)."""
    return statistics.median(s / f for f, s in zip(fake_times(faster, n), fake_times(slower, n)))


@pytest.mark.parametrize("n", SIZES)
def test_every_n_has_the_three_ratios_of_issue_24(figures, n):
    assert figures[f"kinematics_vs_pylinkage_numba_n{n}"] == pytest.approx(
        ratio("fourbar_kinematics", "pylinkage_numba_kinematics", n), rel=1e-12)
    assert figures[f"positions_vs_pylinkage_numba_n{n}"] == pytest.approx(
        ratio("fourbar_positions", "pylinkage_numba_positions", n), rel=1e-12)
    assert figures[f"handfused_over_ours_kinematics_n{n}"] == pytest.approx(
        ratio("handfused_kinematics", "fourbar_kinematics", n), rel=1e-12)


def test_the_call_at_n12_and_the_keys_of_earlier_runs(figures):
    assert figures["fourbar_call_n12_s"] == pytest.approx(statistics.median(fake_times("fourbar_kinematics", 12)))
    # the unsuffixed keys are the main N's (here 1e5)
    assert figures["kinematics_vs_pylinkage_numba"] == figures["kinematics_vs_pylinkage_numba_n100000"]
    assert figures["fourbar_kinematics_per_s"] == pytest.approx(
        1e5 / statistics.median(fake_times("fourbar_kinematics", 100_000)))
    assert figures["shaper_reactions_per_s"] == pytest.approx(1e5 / 0.5)
    assert figures["variants_kinematics_per_s"] == pytest.approx(120_000 / 0.025)
    assert figures["peak_memory_over_result"] == pytest.approx(1.5)
    for key in ("kinematics_vs_pylinkage_plain", "positions_vs_pylinkage_numba", "kinematics_vs_handfused",
                "handfused_over_ours_kinematics", "positions_vs_handfused", "kinematics_vs_pylinkage_numba_points",
                "pylinkage_numba_kinematics_per_s", "pylinkage_plain_kinematics_per_s", "peak_memory_1e6_bytes"):
        assert figures[key] is not None, key


def test_one_goal_row_per_goal_per_n_met_or_missed_by_the_right_factor(figures):
    goals = figures["goals"]
    rows = {(g["figure"], g["goal"]) for g in goals.values()}
    assert len(rows) == len(goals)
    expected = {f"kinematics_vs_pylinkage_numba_n{n}" for n in SIZES}
    assert {g["figure"] for g in goals.values() if ">= 1x pylinkage + numba" in g["goal"]
            and "full" in g["goal"]} == expected
    assert {g["figure"] for g in goals.values() if ">= 2x" in g["goal"]} == {
        "kinematics_vs_pylinkage_numba_n10000", "kinematics_vs_pylinkage_numba_n100000"}
    assert {g["figure"] for g in goals.values() if "positions only" in g["goal"]} == {
        f"positions_vs_pylinkage_numba_n{n}" for n in (360, 10_000, 100_000)}
    assert {g["figure"] for g in goals.values() if "hand-fused" in g["goal"]} == {
        "handfused_over_ours_kinematics_n10000", "handfused_over_ours_kinematics_n100000"}
    # N = 12: ours 0.5 ms + 12 us against 10 us + 9.6 us: missed by that factor
    n12 = goals["kinematics_vs_pylinkage_numba_n12>=1"]
    assert n12["met"] is False
    assert n12["missed_by_factor"] == pytest.approx(1 / ratio("fourbar_kinematics", "pylinkage_numba_kinematics", 12))
    # N = 1e5: ours 0.1005 s against 0.08001 s: 0.8x, missed by 1.25x (>= 1) and 2.5x (>= 2)
    r = ratio("fourbar_kinematics", "pylinkage_numba_kinematics", 100_000)
    assert goals["kinematics_vs_pylinkage_numba_n100000>=2"]["missed_by_factor"] == pytest.approx(2 / r)
    call = goals["fourbar_call_n12_s<=4e-05"]
    assert call["met"] is False
    assert call["missed_by_factor"] == pytest.approx(statistics.median(fake_times("fourbar_kinematics", 12)) / 4e-5)
    assert goals["newton_sweep_speedup>=5"]["met"] is True
    assert goals["peak_memory_over_result<=2"]["met"] is True
    variants = goals["variants_kinematics_per_s>=5e+06"]                  # 120 000 / 0.025 s = 4.8e6 /s
    assert variants["met"] is False
    assert variants["missed_by_factor"] == pytest.approx(5e6 / 4.8e6)


def test_a_missing_peer_leaves_null_figures_and_unmet_goals_unjudged(contenders):
    ours_only = {k: c for k, c in contenders.items() if "pylinkage" not in k}
    figures = bench.summary(ours_only, SIZES, 100_000)
    for n in SIZES:
        assert figures[f"kinematics_vs_pylinkage_numba_n{n}"] is None
        assert figures[f"handfused_over_ours_kinematics_n{n}"] is not None
    assert figures["goals"]["kinematics_vs_pylinkage_numba_n360>=1"]["met"] is None


def test_calls_per_run_fills_the_round_time():
    requested = []

    def run(calls):                  # a call of 1 ms
        requested.append(calls)
        return 1e-3

    assert bench.calls_per_run(run, 0.05) == 50
    assert requested == [1, 4, 16]   # 16 calls (16 ms) pass a quarter of 50 ms
    assert bench.calls_per_run(lambda calls: 2.0, 0.05) == 1
    assert bench.calls_per_run(lambda calls: 1e-9, 0.05) == bench.MAX_CALLS


# ----------------------------------------------------------------------------------------------
# 2. trade.py on slide inputs and on every shipped scheme
# ----------------------------------------------------------------------------------------------

STROKE = (0.32, 0.48)  # m, schemes/piston_driven_crank.toml: range = [0.48, 0.32]


def test_a_slide_input_is_swept_over_its_stroke_in_metres():
    mech = linkage.load("piston_driven_crank")
    margin = 0.3                                                      # rad of the equivalent turn
    sweep = trade.input_sweep(mech, 9, margin=margin)
    inset = margin * (STROKE[1] - STROKE[0]) / (2 * math.pi)          # m
    assert sweep.slide
    assert sweep.scale == pytest.approx((STROKE[1] - STROKE[0]) / (2 * math.pi), rel=1e-12)
    np.testing.assert_allclose(sweep.values, np.linspace(STROKE[0] + inset, STROKE[1] - inset, 9), rtol=0,
                               atol=1e-15)
    crank = trade.input_sweep(linkage.load("four_bar"), 8)
    assert not crank.slide and crank.scale == 1.0
    np.testing.assert_allclose(np.diff(crank.values), 2 * math.pi / 8, rtol=1e-12)


def test_the_finite_differences_of_a_slide_input_follow_the_five_point_law():
    rows = {r.h: r for r in trade.analog_study(["piston_driven_crank"], steps=(3e-2, 1e-2), positions=6)}
    assert all(r.slide for r in rows.values())
    for r in rows.values():
        assert np.isfinite(r.first) and np.isfinite(r.second)
    # truncation ~ h^4: a third of the step, 81 times smaller (the step is h * stroke / 2 pi metres;
    # a step in metres of h itself, 0.03 m on a 0.16 m stroke, would be far off this law)
    assert 40 < rows[3e-2].first / rows[1e-2].first < 160
    assert 40 < rows[3e-2].second / rows[1e-2].second < 160
    assert rows[1e-2].first < 1e-8


def test_every_shipped_scheme_runs_in_the_analogs_study():
    rows = trade.analog_study(steps=(1e-2,), positions=4)
    assert {r.scheme for r in rows} == set(linkage.shipped_schemes())
    for r in rows:
        assert np.isfinite(r.first) and np.isfinite(r.second) and r.first < 1e-5, r
    slides = {r.scheme for r in rows if r.slide}
    assert {"piston_driven_crank", "cylinder_boom"} <= slides
    text = "\n".join(trade.analog_lines(rows, "x.png"))
    assert "over its declared stroke in metres" in text and "piston_driven_crank (*slide*)" in text


# ----------------------------------------------------------------------------------------------
# 3. the README's benchmark command
# ----------------------------------------------------------------------------------------------


def test_the_readme_benchmark_command_is_the_one_run_py_documents():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Accuracy and speed", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```\n(.*?)```", section, re.DOTALL)
    commands = [line.split("&&")[-1].strip() for block in blocks for line in block.splitlines()
                if "benchmarks/run.py" in line]
    assert commands == [bench.README_COMMAND]
    assert bench.README_COMMAND in bench.__doc__
    args = bench.parse_args(bench.README_COMMAND.split()[2:])
    assert args.quick and not args.no_peers
    settings = bench.settings_for(args.quick, args.rounds, args.positions)
    assert set(SIZES) <= set(settings.sizes)
