"""The speed/accuracy studies of ``benchmarks/trade.py``, run reduced, against independent oracles.

1. Quadrature rules against integrals known in closed form (the trapezoid rule's exact error on
   ``psi^2``, Simpson's exactness on cubics); the adaptive cycle work against Simpson's rule on a
   fine table (two independent rules).
2. The number of positions: errors shrink with n, as n^-2 on the course press; the cycle work at
   large n converges to the adaptive value.
3. The observed orders of the quadrature study: 2 for the trapezoid rule, 4 for Simpson's rule on
   the press (kinks on the samples), 2 for every rule on the flying shears (kinks between them).
4. Newton's method on the four-bar's RRR dyad against the triangle construction written here, its
   quadratic convergence, and against the library's closed form for every dyad kind.
5. The methods study: the ODE steady state under the balancing constant moment shows the delta the
   exact method sized for; the course method's flywheel gives a larger one on the press.
6. The ODE tolerances: a tighter rtol gives a smaller error.
7. Finite differences of the analogs shrink as h^4 where truncation dominates.
8. The markdown and the pictures of a reduced study are written.
"""

from __future__ import annotations

import importlib.util
import itertools
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import linkage
from assur.base import global_point

ROOT = Path(__file__).resolve().parent.parent


def _load_trade():
    """``benchmarks/trade.py`` (a script folder, not a package) as the module ``trade``."""
    if "trade" in sys.modules:
        return sys.modules["trade"]
    spec = importlib.util.spec_from_file_location("trade", ROOT / "benchmarks" / "trade.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["trade"] = module  # dataclasses look their module up while the file runs
    spec.loader.exec_module(module)
    return module


trade = _load_trade()
PRESS, SHEARS = "course_slider_crank", "flying_shears"


@pytest.fixture(scope="module")
def press_positions():
    return trade.positions_study([PRESS], counts=(12, 72, 360), reference=3600, check=None, repeat=1)[PRESS]


@pytest.fixture(scope="module")
def quadrature():
    return trade.quadrature_study([PRESS, SHEARS], counts=(24, 72, 360, 3600))


# ----------------------------------------------------------------------------------------------
# 1. quadrature rules
# ----------------------------------------------------------------------------------------------


def test_quadratures_against_closed_forms():
    n = 24
    psi = np.linspace(0, 2 * np.pi, n + 1)
    h = psi[1] - psi[0]
    square = trade.quadratures(psi, psi**2)
    exact = (2 * np.pi) ** 3 / 3
    # trapezoid error of f = psi^2 is exactly (b - a) h^2 f'' / 12 = 2 pi h^2 / 6
    assert square["trapezoid"] - exact == pytest.approx(2 * np.pi * h * h / 6, rel=1e-10)
    cubic = trade.quadratures(psi, psi**3 - 2 * psi)
    exact_cubic = (2 * np.pi) ** 4 / 4 - (2 * np.pi) ** 2
    assert cubic["simpson"] == pytest.approx(exact_cubic, rel=1e-13)
    assert cubic["spline"] == pytest.approx(exact_cubic, rel=1e-13)  # not-a-knot reproduces cubics


def test_adaptive_cycle_work_against_simpson_on_a_fine_table(quadrature):
    # the press's load is linear between its 13 table positions: Simpson on 3600 steps (150 per
    # table step, an even number) integrates it to O(h^4), an independent rule
    mech = linkage.load(PRESS)
    psi = np.linspace(0, 2 * np.pi, 3601)
    ends = np.zeros(3601, bool)
    ends[-1] = True
    values = trade.resisting_moment(mech, psi, ends)
    h = psi[1] - psi[0]
    simpson = h / 3 * (values[0] + values[-1] + 4 * values[1:-1:2].sum() + 2 * values[2:-1:2].sum())
    assert quadrature[PRESS]["reference"] == pytest.approx(simpson, rel=1e-10)


# ----------------------------------------------------------------------------------------------
# 2. the number of positions
# ----------------------------------------------------------------------------------------------


def test_errors_shrink_with_n_as_n_squared(press_positions):
    rows, ref = press_positions["rows"], press_positions["reference"]
    for key in ("work", "driving", "flywheel", "delta"):
        errors = [abs(r.errors(ref)[key]) for r in rows]
        assert errors[0] > errors[1] > errors[2] > 0, key
        # from 72 to 360 positions, an error of order 2 falls by (360/72)^2 = 25 (the reference at
        # 3600 positions carries 1/100 of the error at 360 itself)
        assert 15 < errors[1] / errors[2] < 40, key


def test_course_n_12_misses_the_press_flywheel(press_positions):
    rows, ref = press_positions["rows"], press_positions["reference"]
    twelve = rows[0].errors(ref)
    assert twelve["flywheel"] < -0.5  # the 12-step trapezoid misses most of the load's work
    assert twelve["delta"] > 0.3      # so the machine fluctuates more than it was sized for


def test_cycle_work_converges_to_the_adaptive_value(press_positions, quadrature):
    work = press_positions["reference"].work  # trapezoid on 3600 steps
    assert work == pytest.approx(quadrature[PRESS]["reference"], rel=1e-5)
    # and the driving moment balances it: no driving load is declared
    assert press_positions["reference"].driving == pytest.approx(-work / (2 * np.pi), rel=1e-12)


def test_smallest_good():
    assert trade._smallest_good([12, 24, 72, 360], [0.001, 0.5, 0.005, 0.0001]) == 72
    assert trade._smallest_good([12, 24], [0.5, 0.2]) is None


# ----------------------------------------------------------------------------------------------
# 3. observed orders
# ----------------------------------------------------------------------------------------------


def _order(study, name, rule, n1, n2):
    e = study[name]["errors"]
    return math.log(abs(e[n1][rule]) / abs(e[n2][rule])) / math.log(n2 / n1)


def test_observed_orders(quadrature):
    assert _order(quadrature, PRESS, "trapezoid", 360, 3600) == pytest.approx(2, abs=0.05)
    assert _order(quadrature, PRESS, "simpson", 360, 3600) == pytest.approx(4, abs=0.1)
    for rule in ("trapezoid", "simpson", "spline"):
        assert _order(quadrature, SHEARS, rule, 360, 3600) == pytest.approx(2, abs=0.6), rule


def test_observed_order_helper():
    assert trade.observed_order([10, 100], [1e-2, 1e-6]) == [pytest.approx(4.0)]
    assert math.isnan(trade.observed_order([10, 100], [0.0, 1e-6])[0])


# ----------------------------------------------------------------------------------------------
# 4. Newton's method
# ----------------------------------------------------------------------------------------------


def _four_bar_b(phi):
    """B of the four-bar (O at the origin, C = (0.3, 0), OA = 0.1, AB = 0.3, CB = 0.25) by the
    triangle A-B-C, B on the left of A -> C."""
    a = 0.1 * np.column_stack([np.cos(phi), np.sin(phi)])
    c = np.array([0.3, 0.0])
    d = np.linalg.norm(c - a, axis=1)
    e = (c - a) / d[:, None]
    along = (0.3**2 - 0.25**2 + d**2) / (2 * d)
    height = np.sqrt(0.3**2 - along**2)
    return a + along[:, None] * e + height[:, None] * np.column_stack([-e[:, 1], e[:, 0]])


def test_newton_on_the_four_bar_against_the_triangle():
    mech = linkage.load("four_bar")
    group = linkage.structure_of(mech).groups[0]
    phi = np.radians(np.arange(0.0, 360.0, 7.5))
    motion = linkage.analyze(mech, phi, order=0)
    known = {k: motion.poses[k] for k in group.known_links}
    rng = np.random.default_rng(3)
    start = {k: motion.poses[k] + rng.uniform(-0.02, 0.02, (len(phi), 3)) for k in group.links}
    poses, steps, history = trade.newton_solve(group, known, start)
    b = global_point(poses["3"], mech.links["3"].points["B"])
    assert np.max(np.abs(b - _four_bar_b(phi))) < 1e-12 * mech.size
    assert steps.max() <= 6
    # quadratic convergence while the residual is above round-off
    for r0, r1 in itertools.pairwise(history):
        if r0 > 1e-7:
            assert r1 <= 100 * r0**2
    assert history[-1] < 1e-14


def test_newton_against_the_closed_form_for_every_kind():
    kinds = trade.newton_schemes()
    assert set(kinds) == {"RRR", "RRP", "RPR", "PRP", "RPP"}
    assert kinds["RRR"] == ("four_bar", 0)
    for name, index in kinds.values():
        result = trade.newton_group(name, index, positions=24, repeat=1)
        assert result.batch_error < 1e-12, name
        assert result.continuation_error < 1e-12, name
        assert result.batch_iterations <= 8, name


def test_newton_reports_no_convergence():
    mech = linkage.load("four_bar")
    group = linkage.structure_of(mech).groups[0]
    motion = linkage.analyze(mech, [0.3], order=0)
    known = {k: motion.poses[k] for k in group.known_links}
    start = {k: motion.poses[k] + 0.05 for k in group.links}
    with pytest.raises(linkage.AssemblyError, match="did not converge"):
        trade.newton_solve(group, known, start, max_iterations=1)


# ----------------------------------------------------------------------------------------------
# 5. and 6. methods and tolerances
# ----------------------------------------------------------------------------------------------


def test_methods_on_the_press():
    res = trade.methods_study([PRESS], repeat=1)[PRESS]
    target = linkage.dynamics.dynamics_of(linkage.load(PRESS)).delta
    # no motor: the steady state under the balancing moment is the energy solution the exact
    # method sized, so it shows the target delta; the course flywheel (n = 12) is too small
    assert res.laws["ode_exact"].delta_actual == pytest.approx(target, rel=1e-3)
    assert res.laws["ode_course"].delta_actual > 1.3 * target
    assert res.speed_difference("exact", "ode_exact") < 1e-4
    assert res.speed("course").shape == (13,)
    assert res.speed("exact").shape == (13,)


def test_tolerances_tighter_is_better():
    rows = trade.tolerance_study([PRESS], (1e-4, 1e-8), 1e-11)[PRESS]["rows"]
    assert rows[1].error < rows[0].error
    assert rows[1].error < 1e-5
    assert all(r.seconds > 0 for r in rows)


# ----------------------------------------------------------------------------------------------
# 7. analogs
# ----------------------------------------------------------------------------------------------


def test_finite_differences_of_the_analogs_shrink_as_h4():
    rows = {r.h: r for r in trade.analog_study(["four_bar"], steps=(1e-1, 5e-2, 1e-3))}
    ratio = rows[1e-1].first / rows[5e-2].first
    assert 16 / 2 < ratio < 16 * 2     # truncation of 5-point differences: h^4
    assert rows[1e-3].first < 1e-10
    assert rows[1e-3].second < 1e-7


# ----------------------------------------------------------------------------------------------
# 8. markdown and pictures
# ----------------------------------------------------------------------------------------------


def test_markdown_and_pictures(press_positions, quadrature, tmp_path):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    study = {PRESS: press_positions}
    lines = trade.positions_lines(study, "docs/images/trade_positions.png")
    text = "\n".join(lines)
    assert "| n | time (ms) |" in text and "**Recommendation.**" in text
    assert "n ≥ 360" in text  # 72 positions miss the 1 % on the press's flywheel
    trade.positions_figure(study, tmp_path / "positions.png")
    trade.quadrature_figure(quadrature, tmp_path / "quadrature.png")
    assert (tmp_path / "positions.png").stat().st_size > 10_000
    assert (tmp_path / "quadrature.png").stat().st_size > 10_000
    assert "Simpson" in "\n".join(trade.quadrature_lines(quadrature, "docs/images/trade_quadrature.png"))
