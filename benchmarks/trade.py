"""The speed/accuracy trade of the library, measured: what each choice costs and what it buys.

Run ``python benchmarks/trade.py`` (the full run, about a minute on 2 cores) or
``python benchmarks/trade.py --quick`` (about 40 s); ``--out FILE`` writes the markdown there
instead of printing it. ``python benchmarks/run.py --quick`` calls :func:`run` and appends its
lines to ``benchmarks/RESULTS.md``. Every study also writes one picture,
``docs/images/trade_<study>.png``; ``docs/speed_accuracy.md`` explains the figures.

The studies:

1. ``positions``: the number of table positions n against the errors of the cycle work of the
   resisting forces, the driving moment, the flywheel and the coefficient of speed fluctuation
   delta, for every shipped scheme with a ``[dynamics]`` section;
2. ``quadrature``: the trapezoid rule (the course's) against Simpson's rule and a cubic spline
   on the same samples, for the cycle work of the resistance;
3. ``methods``: Mertsalov's course method, the exact energy method and the equation of motion
   integrated to its steady state;
4. ``tolerances``: the relative tolerance of ``solve_ivp`` against the error of the steady-state
   speed and the time it takes;
5. ``newton``: the closed form of each dyad kind against Newton's method on the group's
   constraint equations;
6. ``analogs``: the exact analogs against 5-point finite differences of the positions.

Times are the best of a few runs on the machine at hand (shared, noisy): compare the ratios.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy.integrate import simpson
from scipy.interpolate import CubicSpline

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:  # run as a script from a checkout
    sys.path.insert(0, str(ROOT))

import linkage
from assur import Group
from assur.dyad import Dyad
from linkage.dynamics import course_method, dynamics_of, exact_method, steady_state
from linkage.errors import AssemblyError, LinkageError, SchemeError
from linkage.kinematics.motion import BranchWarning
from linkage.dynamics.reduced import reduced_characteristics

__all__ = [
    "AnalogRow",
    "InputSweep",
    "MethodsResult",
    "NewtonResult",
    "PositionsRow",
    "ToleranceRow",
    "adaptive_cycle_work",
    "analog_study",
    "dynamics_schemes",
    "input_sweep",
    "main",
    "methods_study",
    "newton_schemes",
    "newton_solve",
    "newton_study",
    "positions_row",
    "positions_study",
    "quadrature_study",
    "quadratures",
    "resisting_moment",
    "run",
    "tolerance_study",
]

#: where the pictures go
IMAGES = ROOT / "docs" / "images"
#: table positions per revolution of the positions and quadrature studies
POSITIONS = (12, 24, 36, 72, 360, 3600)
#: the converged reference of the positions study, and the run that checks its convergence
REFERENCE_POSITIONS = 36000
CHECK_POSITIONS = 18000
#: relative tolerances of the tolerances study (quick / full) and of its reference
TOLERANCES = {True: (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9), False: (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9,
                                                                         1e-10)}
REFERENCE_RTOL = {True: 1e-11, False: 1e-12}
#: positions of a turn the Newton study solves
NEWTON_POSITIONS = 360
#: steps of the finite differences of the analogs study, rad
STEPS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5)
#: the relative error a recommendation aims at
TARGET = 0.01
EPS = float(np.finfo(float).eps)


# ----------------------------------------------------------------------------------------------
# small helpers
# ----------------------------------------------------------------------------------------------


def best_time(fn: Callable[..., Any], *args: Any, repeat: int = 3, **kwargs: Any) -> tuple[float, Any]:
    """The shortest wall time (s) of ``repeat`` calls ``fn(*args, **kwargs)`` and the last result."""
    best, result = math.inf, None
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        result = fn(*args, **kwargs)
        best = min(best, time.perf_counter() - t0)
    return best, result


def relative(value: float, reference: float) -> float:
    """``(value - reference) / |reference|``."""
    return (value - reference) / abs(reference)


def _sci(x: float, digits: int = 1) -> str:
    """A signed relative error in scientific notation (``+3.4e-01``; ``0`` for an exact zero)."""
    if x == 0:
        return "0"
    return f"{x:+.{digits}e}"


def _percent(x: float) -> str:
    """A signed relative error in percent with two significant digits (``-88 %``, ``+0.062 %``)."""
    return f"{100 * x:+.2g} %".replace("e-0", "e-").replace("-", "−")


def _ms(seconds: float) -> str:
    ms = seconds * 1e3
    return f"{ms:.3g}" if ms < 100 else f"{ms:.0f}"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """A markdown table."""
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)] + [
        "| " + " | ".join(row) + " |" for row in rows]


def dynamics_schemes() -> list[str]:
    """The shipped schemes that declare a ``[dynamics]`` section, in the order of
    :func:`linkage.shipped_schemes`."""
    names = []
    for name in linkage.shipped_schemes():
        try:
            dynamics_of(linkage.load(name))
        except SchemeError:
            continue
        names.append(name)
    return names


def _cycle_start(mech: linkage.Mechanism) -> tuple[float, int]:
    """``(phi0, s)``: the input angle of position 1 (rad) and the sense of rotation."""
    spec = dynamics_of(mech)
    return float(linkage.table_angles(mech, 1, spec.start, spec.rotation)[0]), spec.rotation


def _smallest_good(counts: Sequence[int], errors: Sequence[float], target: float = TARGET) -> int | None:
    """The smallest n of ``counts`` from which on every error is within ``target``."""
    good = None
    for n, e in zip(counts[::-1], errors[::-1]):
        if not abs(e) <= target:
            break
        good = n
    return good


def _figure(height: float):
    from linkage.report.style import PAGE_WIDTH, new_figure

    return new_figure(PAGE_WIDTH, height)


def _save(fig, path: Path | None) -> None:
    from linkage.report.style import pyplot

    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=150)
    pyplot().close(fig)


def _loglog(ax, xlabel: str, ylabel: str) -> None:
    from matplotlib.ticker import NullFormatter

    from linkage.report.style import FONT, SMALL

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel, fontsize=FONT)
    ax.set_ylabel(ylabel, fontsize=FONT)
    ax.tick_params(labelsize=SMALL)
    ax.grid(True, which="major", alpha=0.35)
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())


def _slope(ax, x: np.ndarray, anchor: tuple[float, float], power: float, label: str, style: str = ":") -> None:
    """A reference line ``y ∝ x^power`` through ``anchor``."""
    x = np.asarray(x, dtype=float)
    ax.plot(x, anchor[1] * (x / anchor[0]) ** power, style, color="0.45", lw=1.1, label=label)


def _legend_below(fig, axes, ncols: int = 2) -> None:
    from linkage.report.style import SMALL

    handles, labels = [], []
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="outside lower center", fontsize=SMALL, ncols=ncols, frameon=False)


def _nonzero(x, y):
    """The points with a positive, finite ``y`` (zeros have no place on a log axis)."""
    x, y = np.asarray(x, dtype=float), np.abs(np.asarray(y, dtype=float))
    keep = np.isfinite(y) & (y > 0)
    return x[keep], y[keep]


def _nice(name: str) -> str:
    """A scheme's name in words for legends: ``course_slider_crank`` -> ``course slider crank``."""
    return name.replace("_", " ")


# ----------------------------------------------------------------------------------------------
# 1. the number of table positions
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PositionsRow:
    """The course method on n table positions.

    Attributes
    ----------
    scheme : str
    n : int
        Table positions per revolution.
    seconds : float
        Wall time of :func:`linkage.dynamics.cycle.course_method`, s.
    work : float
        Cycle work of the resisting forces (gravity included), trapezoid on the n steps, J.
    driving : float
        Constant driving moment that balances the cycle, N·m.
    flywheel : float
        Flywheel ``I' - I_0`` Mertsalov's method asks for, kg·m² (negative: none needed).
    delta : float
        The coefficient of speed fluctuation a machine fitted with that flywheel really has: the
        exact energy solution on the exact method's default grid of 3600 steps (the same for every n).
    delta_seconds : float
        Wall time of that exact energy solution, s.
    """

    scheme: str
    n: int
    seconds: float
    work: float
    driving: float
    flywheel: float
    delta: float
    delta_seconds: float

    def errors(self, reference: PositionsRow) -> dict[str, float]:
        """Relative errors of the four results against ``reference``."""
        return {key: relative(getattr(self, key), getattr(reference, key))
                for key in ("work", "driving", "flywheel", "delta")}


def positions_row(mech: linkage.Mechanism, n: int, repeat: int = 3) -> PositionsRow:
    """The course method of ``mech`` on ``n`` table positions (:class:`PositionsRow`)."""
    seconds, law = best_time(course_method, mech, positions=n, repeat=repeat)
    step = 2 * np.pi / n
    resisting = law.reduced.moment_resistance
    work = float(np.sum(resisting[1:] + resisting[:-1]) * step / 2)
    flywheel = law.required_constant_inertia - law.reduced.inertia_constant
    spec = dynamics_of(mech)
    fitted = replace(spec, delta=None, flywheel=spec.flywheel + max(flywheel, 0.0))
    delta_seconds, fine = best_time(exact_method, mech, fitted, repeat=1)
    return PositionsRow(mech.name, n, seconds, work, law.driving_moment, flywheel, fine.delta_actual, delta_seconds)


def positions_study(names: Sequence[str], counts: Sequence[int] = POSITIONS, reference: int = REFERENCE_POSITIONS,
                    check: int | None = CHECK_POSITIONS, repeat: int = 3) -> dict[str, dict[str, Any]]:
    """The positions study of each scheme of ``names``.

    Returns
    -------
    dict of scheme name -> dict
        ``"rows"``: a :class:`PositionsRow` per n of ``counts``; ``"reference"``: the row at
        ``reference`` positions; ``"check"``: ``check``; ``"reference_error"``: None without
        ``check``, else the largest relative change of the four results from ``check`` to
        ``reference`` positions divided by ``(reference / check)^2 - 1``, the reference's own error
        if the results converge as n^-2 (Richardson).
    """
    out = {}
    for name in names:
        mech = linkage.load(name)
        rows = [positions_row(mech, n, repeat) for n in counts]
        ref = positions_row(mech, reference, 1)
        entry: dict[str, Any] = {"rows": rows, "reference": ref, "check": check, "reference_error": None}
        if check is not None:
            coarse = positions_row(mech, check, 1)
            factor = (reference / check) ** 2 - 1
            entry["reference_error"] = max(abs(e) for e in coarse.errors(ref).values()) / factor
        out[name] = entry
    return out


def _same_errors(rows: Sequence[PositionsRow], ref: PositionsRow) -> bool:
    """Whether the cycle work and the driving moment have the same size of relative error (no
    driving load is declared, so ``M_d = -A_c / 2 pi``)."""
    sizes = [(abs(r.errors(ref)["work"]), abs(r.errors(ref)["driving"])) for r in rows]
    return all(abs(a - b) <= 1e-6 * a + 1e-12 for a, b in sizes)


def positions_lines(study: dict[str, dict[str, Any]], image: str) -> list[str]:
    """The markdown of the positions study (:func:`positions_study`); ``image``: the picture's path."""
    reference = next(iter(study.values()))["reference"].n
    lines = ["## 1. Number of table positions n", "",
             ("Mertsalov's course method (`course_method`) on n positions; errors relative to the same method "
             f"on n = {reference}. `A_c`: cycle work of the resisting forces (trapezoid), `M_d`: "
             "driving moment, `I_fw`: flywheel `I' − I_0`, `δ`: the coefficient of speed fluctuation a "
             "machine fitted with that flywheel really has (exact energy solution on 3600 points, "
             "`exact_method`, the same grid for every n). Time: the course method."), ""]
    for name, entry in study.items():
        ref = entry["reference"]
        rows = []
        for r in entry["rows"] + [ref]:
            e = r.errors(ref)
            rows.append([f"{r.n}", _ms(r.seconds), _sci(e["work"]), _sci(e["driving"]), _sci(e["flywheel"]),
                         _sci(e["delta"]), f"{r.flywheel:.4g}", f"{r.delta:.4g}"])
        lines += [(f"**{name}** (reference n = {ref.n}: A_c = {ref.work:.6g} J, M_d = {ref.driving:.6g} N·m, "
                  f"I_fw = {ref.flywheel:.6g} kg·m², δ = {ref.delta:.6g})"), ""]
        lines += _table(["n", "time (ms)", "error A_c", "error M_d", "error I_fw", "error δ", "I_fw (kg·m²)",
                         "δ"], rows)
        if entry["reference_error"] is not None:
            check = entry["check"]
            lines += ["", (f"Convergence of the reference: from n = {check} to {ref.n} the results change "
                          f"by at most {entry['reference_error'] * ((ref.n / check) ** 2 - 1):.1e} "
                          f"(relative), so the reference is within about {entry['reference_error']:.0e} of the "
                          "limit (Richardson, errors ∝ n⁻²). The δ check (`exact_method` on 3600 points) takes "
                          f"{_ms(ref.delta_seconds)} ms.")]
        lines.append("")
    lines += [positions_recommendation(study), "", f"Plot: `{image}`", ""]
    return lines


def positions_recommendation(study: dict[str, dict[str, Any]]) -> str:
    """One sentence: per scheme the smallest n from which on the flywheel and delta are within
    :data:`TARGET`, and the errors of the course's n = 12 (flagged when it is within the target
    only by chance, a larger n of the list being outside it)."""
    parts = []
    for name, entry in study.items():
        rows, ref = entry["rows"], entry["reference"]
        counts = [r.n for r in rows]
        worst = [max(abs(r.errors(ref)["flywheel"]), abs(r.errors(ref)["delta"])) for r in rows]
        good = _smallest_good(counts, worst)
        text = f"n ≥ {good}" if good else f"more than {counts[-1]} positions"
        if 12 in counts:
            e = rows[counts.index(12)].errors(ref)
            text += f" (n = 12: {_percent(e['flywheel'])} in the flywheel, {_percent(e['delta'])} in δ"
            worse = [(n, w) for n, w in zip(counts, worst) if n > 12 and w > TARGET]
            if worst[counts.index(12)] <= TARGET and worse:
                text += f", within {100 * TARGET:g} % by chance: n = {worse[0][0]} is off by {100 * worse[0][1]:.2g} %"
            text += ")"
        parts.append(f"{text} for {name}")
    return f"**Recommendation.** For the flywheel and δ to {100 * TARGET:g} % use {'; '.join(parts)}."


def positions_figure(study: dict[str, dict[str, Any]], path: Path | None) -> None:
    """Relative errors against n (log-log), one panel per scheme, and the time per n."""
    from linkage.report.style import CURVE_COLOURS, MARKERS, SMALL

    fig = _figure(6.6)
    grid = fig.add_gridspec(2, len(study), height_ratios=[1.6, 1])
    words = {"work": "cycle work of the resistance $A_c$", "driving": "driving moment $M_d$",
             "flywheel": "flywheel $I_{fw}$", "delta": "δ with that flywheel"}
    axes = []
    for k, (name, entry) in enumerate(study.items()):
        ax = fig.add_subplot(grid[0, k])
        axes.append(ax)
        rows, ref = entry["rows"], entry["reference"]
        n = np.array([r.n for r in rows], dtype=float)
        keys = ["work", "flywheel", "delta"] if _same_errors(rows, ref) else ["work", "driving", "flywheel", "delta"]
        for j, key in enumerate(keys):
            x, y = _nonzero(n, [r.errors(ref)[key] for r in rows])
            label = words[key]
            if key == "work" and "driving" not in keys:
                label = "cycle work $A_c$ and $M_d = -A_c/2\\pi$"
            ax.plot(x, y, "-", marker=MARKERS[j], color=CURVE_COLOURS[j], mfc="white", mew=1.3, lw=1.6, label=label)
        _slope(ax, n, (n[-1], 0.3 * (abs(rows[-1].errors(ref)["flywheel"]) or 1e-6)), -2, "slope $n^{-2}$")
        ax.axhline(TARGET, color="black", ls="--", lw=1.0, label=f"{100 * TARGET:g} % relative error")
        _loglog(ax, "table positions per turn n", "|relative error|" if k == 0 else "")
        ax.set_title(_nice(name), fontsize=SMALL + 1)
        ax.set_xticks(n, [str(int(v)) for v in n])
        ax.minorticks_off()
        ax.tick_params(axis="x", labelrotation=45)
    tax = fig.add_subplot(grid[1, :])
    for k, (name, entry) in enumerate(study.items()):
        n = np.array([r.n for r in entry["rows"]] + [entry["reference"].n], dtype=float)
        t = np.array([r.seconds for r in entry["rows"]] + [entry["reference"].seconds]) * 1e3
        tax.plot(n, t, "-", marker=MARKERS[3 + k], color=("0.15", "0.55")[k % 2], mfc="white", mew=1.3, lw=1.6,
                 label=f"time, {_nice(name)}")
    _loglog(tax, "table positions per turn n", "course method, ms")
    axes.append(tax)
    _legend_below(fig, axes)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# 2. quadrature
# ----------------------------------------------------------------------------------------------


def resisting_moment(mech: linkage.Mechanism, psi: np.ndarray, ends: np.ndarray | None = None) -> np.ndarray:
    """The reduced moment of the resisting forces ``M_c(psi)`` (N·m) at the angles ``psi`` (rad)
    travelled from position 1 in the direction of rotation, shape ``(N,)``."""
    phi0, s = _cycle_start(mech)
    spec = dynamics_of(mech)
    red = reduced_characteristics(mech, phi0 + s * np.asarray(psi, dtype=float), s,
                                  extra_inertia=spec.constant_inertia, ends=ends)
    return red.moment_resistance


def _table_samples(mech: linkage.Mechanism, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``psi`` (n+1,) of the table positions and ``M_c`` there (the last position ends the cycle)."""
    psi = np.arange(n + 1) * 2 * np.pi / n
    ends = np.zeros(n + 1, bool)
    ends[-1] = True
    return psi, resisting_moment(mech, psi, ends)


def quadratures(psi: np.ndarray, values: np.ndarray) -> dict[str, float]:
    """The integral of ``values`` over ``psi`` (equal steps, an even number of them) by the
    trapezoid rule, Simpson's rule and the integral of the not-a-knot cubic spline through them."""
    h = psi[1] - psi[0]
    return {"trapezoid": float(np.sum(values[1:] + values[:-1]) * h / 2),
            "simpson": float(simpson(values, x=psi)),
            "spline": float(CubicSpline(psi, values).integrate(psi[0], psi[-1]))}


def adaptive_cycle_work(mech: linkage.Mechanism, rtol: float = 1e-13, start: int = 12, max_levels: int = 60) -> tuple[float, int]:
    """The cycle work of the resisting forces (J) to ``rtol`` of ``∫|M_c| dpsi``, and the number
    of evaluations: Gauss–Legendre rules of 10 and 20 points on each interval (their difference is
    the error estimate), intervals whose estimate is too large are halved, one vectorised
    evaluation per level. Kinks of the load (table positions, fractions of a force diagram) only
    refine the intervals they lie in."""
    x10, w10 = np.polynomial.legendre.leggauss(10)
    x20, w20 = np.polynomial.legendre.leggauss(20)
    nodes = np.concatenate([x10, x20])
    edges = np.linspace(0, 2 * np.pi, start + 1)
    a, b = edges[:-1], edges[1:]
    total, evaluations, tol = 0.0, 0, None
    for _ in range(max_levels):
        mid, half = (a + b) / 2, (b - a) / 2
        values = resisting_moment(mech, (mid[:, None] + half[:, None] * nodes[None, :]).ravel()).reshape(len(a), -1)
        evaluations += values.size
        g10 = half * (values[:, :10] @ w10)
        g20 = half * (values[:, 10:] @ w20)
        if tol is None:
            tol = rtol * float(np.sum(half * (np.abs(values[:, 10:]) @ w20)))
        done = np.abs(g20 - g10) <= tol * (b - a) / (2 * np.pi)
        total += float(np.sum(g20[done]))
        a, b = a[~done], b[~done]
        if not len(a):
            return total, evaluations
        mid = (a + b) / 2
        a, b = np.concatenate([a, mid]), np.concatenate([mid, b])
    raise LinkageError(f"{mech.name}: the adaptive cycle work did not reach {rtol:g} in {max_levels} levels")


def quadrature_study(names: Sequence[str], counts: Sequence[int] = POSITIONS) -> dict[str, dict[str, Any]]:
    """Per scheme: the reference cycle work (adaptive Gauss–Legendre), its evaluations and time,
    and per n the relative errors of the trapezoid rule, Simpson's rule and the spline."""
    out = {}
    for name in names:
        mech = linkage.load(name)
        seconds, (reference, evaluations) = best_time(adaptive_cycle_work, mech, repeat=1)
        errors = {}
        for n in counts:
            psi, values = _table_samples(mech, n)
            errors[n] = {rule: relative(v, reference) for rule, v in quadratures(psi, values).items()}
        out[name] = {"reference": reference, "evaluations": evaluations, "seconds": seconds, "errors": errors}
    return out


def observed_order(counts: Sequence[int], errors: Sequence[float]) -> list[float]:
    """``log(e_k / e_k+1) / log(n_k+1 / n_k)`` between consecutive ``counts`` (NaN where an error
    is zero)."""
    out = []
    for (n1, e1), (n2, e2) in zip(zip(counts, errors), zip(counts[1:], errors[1:])):
        ok = e1 != 0 and e2 != 0
        out.append(math.log(abs(e1) / abs(e2)) / math.log(n2 / n1) if ok else math.nan)
    return out


RULES = {"trapezoid": "trapezoid rule (the course's)", "simpson": "Simpson's rule",
         "spline": "cubic spline through the samples"}


def quadrature_lines(study: dict[str, dict[str, Any]], image: str) -> list[str]:
    """The markdown of the quadrature study (:func:`quadrature_study`); ``image``: the picture's path."""
    lines = ["## 2. Quadrature of the cycle work", "",
             ("The cycle work of the resisting forces `A_c = ∫ M_c dψ` from the same n + 1 samples of `M_c` by "
             "three rules; errors relative to an adaptive Gauss–Legendre integration (10 and 20 points per "
             "interval, intervals halved until they agree to 1e-13). The order is "
             "`log(e_k / e_k+1) / log(n_k+1 / n_k)` from the row above."), ""]
    for name, entry in study.items():
        counts = list(entry["errors"])
        orders = {rule: observed_order(counts, [entry["errors"][n][rule] for n in counts]) for rule in RULES}
        rows = []
        for k, n in enumerate(counts):
            row = [f"{n}"]
            for rule in RULES:
                order = f" ({orders[rule][k - 1]:.1f})" if k and math.isfinite(orders[rule][k - 1]) else ""
                row.append(_sci(entry["errors"][n][rule]) + order)
            rows.append(row)
        lines += [(f"**{name}** (reference A_c = {entry['reference']:.12g} J from {entry['evaluations']} evaluations "
                  f"in {_ms(entry['seconds'])} ms)"), ""]
        lines += _table(["n", "trapezoid (order)", "Simpson (order)", "cubic spline (order)"], rows) + [""]
    lines += [("Why these orders: a load declared at the 13 table positions of the course press and interpolated "
              "linearly is piecewise linear in φ, so `M_c = F(φ)·x'(φ)` is smooth between table positions and has a "
              "kink at each of them. The trapezoid rule is of order 2 whatever n. Simpson's rule is of order 4 only where "
              "every kink falls on a sample that ends a Simpson pair of steps (n a multiple of 24 for the press); at "
              "n = 12 and 36 a pair of steps straddles a kink and the error jumps back up. The cubic spline is one "
              "curve over the whole turn: a kink anywhere costs it its order, so it stays of order 2 (about half "
              "the trapezoid's error). "
              "The flying shears' cut is a diagram over the stroke of the knife: its kinks fall between table "
              "positions for any n, so every rule is of order 2 there and a higher-order rule buys little."), "",
              quadrature_recommendation(study), "", f"Plot: `{image}`", ""]
    return lines


def quadrature_recommendation(study: dict[str, dict[str, Any]]) -> str:
    """One sentence: when a higher-order rule pays, and the n each rule needs for 1e-4."""
    parts = []
    for name, entry in study.items():
        counts = list(entry["errors"])
        trap = _smallest_good(counts, [entry["errors"][n]["trapezoid"] for n in counts], 1e-4)
        simp = _smallest_good(counts, [entry["errors"][n]["simpson"] for n in counts], 1e-4)
        parts.append(f"{name}: trapezoid n ≥ {trap}, Simpson n ≥ {simp}")
    return ("**Recommendation.** Keep the trapezoid rule and choose n: Simpson's rule pays only where the load "
            "has no kink inside a pair of steps (a table load with n a multiple of twice the table's steps); the "
            "cycle work to 1e-4 needs (" + "; ".join(parts) + ").")


def quadrature_figure(study: dict[str, dict[str, Any]], path: Path | None) -> None:
    """Relative error of the cycle work against n (log-log) per rule, one panel per scheme."""
    from linkage.report.style import CURVE_COLOURS, MARKERS, SMALL

    fig = _figure(4.6)
    axes = fig.subplots(1, len(study), squeeze=False)[0]
    for ax, (name, entry) in zip(axes, study.items()):
        counts = np.array(list(entry["errors"]), dtype=float)
        for j, (rule, words) in enumerate(RULES.items()):
            x, y = _nonzero(counts, [entry["errors"][int(n)][rule] for n in counts])
            ax.plot(x, y, ("-", "-", "--")[j], marker=MARKERS[j], color=CURVE_COLOURS[j], mfc="white", mew=1.3,
                    lw=1.6, label=words)
        top = 0.2 * abs(entry["errors"][int(counts[0])]["trapezoid"])  # below the curves, not on them
        _slope(ax, counts, (counts[0], top), -2, "slope $n^{-2}$", ":")
        _slope(ax, counts, (counts[0], top), -4, "slope $n^{-4}$", "-.")
        _loglog(ax, "table positions per turn n", "|relative error of $A_c$|" if ax is axes[0] else "")
        ax.set_ylim(bottom=max(1e-17, ax.get_ylim()[0]))
        ax.set_title(_nice(name), fontsize=SMALL + 1)
        ax.set_xticks(counts, [str(int(v)) for v in counts])
        ax.minorticks_off()
        ax.tick_params(axis="x", labelrotation=45)
    _legend_below(fig, axes)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# 3. Mertsalov vs the exact energy method vs the equation of motion
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MethodsResult:
    """The three methods on one scheme.

    ``laws`` maps ``"course"``, ``"exact"``, ``"ode_course"`` (the steady state of the equation of
    motion with the course method's flywheel) and ``"ode_exact"`` (with the exact one) to
    :class:`linkage.dynamics.cycle.LawOfMotion` at ``fine`` positions (the course method at its declared n),
    ``seconds`` to the wall time of each (s); ``n`` is the declared number of positions and
    ``stride`` picks them out of the ``fine`` ones.
    """

    scheme: str
    n: int
    fine: int
    laws: dict[str, Any]
    seconds: dict[str, float]

    @property
    def stride(self) -> int:
        return self.fine // self.n

    def speed(self, key: str) -> np.ndarray:
        """|omega| (rad/s) at the declared table positions, ``(n + 1,)``."""
        w = np.abs(self.laws[key].omega)
        return w if key == "course" else w[:: self.stride]

    def speed_difference(self, key: str, against: str) -> float:
        """``max |w_key - w_against| / w_m`` over the table positions."""
        wm = abs(dynamics_of(linkage.load(self.scheme)).mean_speed)
        return float(np.max(np.abs(self.speed(key) - self.speed(against))) / wm)


def methods_study(names: Sequence[str], repeat: int = 3) -> dict[str, MethodsResult]:
    """Mertsalov's method, the exact energy method and the ODE steady state on each scheme."""
    out = {}
    for name in names:
        mech = linkage.load(name)
        n = dynamics_of(mech).positions
        fine = n * math.ceil(360 / n)
        seconds, laws = {}, {}
        seconds["course"], laws["course"] = best_time(course_method, mech, repeat=repeat)
        seconds["exact"], laws["exact"] = best_time(exact_method, mech, positions=fine, repeat=repeat)
        for key in ("course", "exact"):
            constant = laws[key].constant_inertia
            seconds[f"ode_{key}"], laws[f"ode_{key}"] = best_time(
                steady_state, mech, constant_inertia=constant, positions=fine, repeat=repeat)
        out[name] = MethodsResult(name, n, fine, laws, seconds)
    return out


def methods_lines(study: dict[str, MethodsResult], image: str) -> list[str]:
    """The markdown of the methods study (:func:`methods_study`); ``image``: the picture's path."""
    lines = ["## 3. Mertsalov's method, the exact energy method and the equation of motion", "",
             ("Course: Mertsalov's method on the declared table positions (`course_method`); exact: the energy "
             "equation on 3600 points (`exact_method`); ODE: the equation of motion with the declared motor "
             "(a constant moment where none is declared) integrated to its periodic steady state "
             "(`steady_state`, rtol 1e-9) with the flywheel each method sized. `δ promised`: the target "
             "the flywheel was sized for; `δ in the ODE`: what the machine fitted with it really shows; "
             "`Δω`: the largest difference of the speed at the table positions from the ODE's with the same "
             "flywheel, relative to the mean speed."), ""]
    rows = []
    for name, res in study.items():
        spec = dynamics_of(linkage.load(name))
        for key, words in (("course", f"course (n = {res.n})"), ("exact", "exact energy")):
            law, ode = res.laws[key], res.laws[f"ode_{key}"]
            flywheel = law.flywheel_inertia or 0.0
            rows.append([name, words, f"{law.driving_moment:.5g}", f"{flywheel:.5g}", f"{spec.delta:.4g}",
                         f"{ode.delta_actual:.4g}", f"{abs(ode.details['mean_speed']):.5g}",
                         _sci(res.speed_difference(key, f"ode_{key}")), _ms(res.seconds[key]),
                         _ms(res.seconds[f"ode_{key}"])])
    lines += _table(["scheme", "method", "M_d (N·m)", "I_fw (kg·m²)", "δ promised", "δ in the ODE",
                     "ODE mean speed (rad/s)", "Δω", "time (ms)", "ODE time (ms)"], rows)
    lines += ["", ("M_d of the ODE rows is the motor's moment averaged over the cycle; with a motor (the flying "
                  "shears) the machine runs at the speed where the motor's characteristic meets the load, "
                  "not at the declared mean speed, and its δ differs from the energy methods' for that reason."), "",
              methods_recommendation(study), "", f"Plot: `{image}`", ""]
    return lines


def methods_recommendation(study: dict[str, MethodsResult]) -> str:
    """One sentence: which method sizes the flywheel, what Mertsalov's is off by, when to run the ODE."""
    parts = []
    for name, res in study.items():
        course, exact = res.laws["course"], res.laws["exact"]
        ratio = (course.flywheel_inertia or 0.0) / (exact.flywheel_inertia or math.nan) - 1
        parts.append(f"{_percent(ratio)} for {name} (n = {res.n}; {_ms(res.seconds['course'])} ms against "
                     f"{_ms(res.seconds['exact'])} ms)")
    return ("**Recommendation.** Size the flywheel by the exact energy method, which costs tens of milliseconds: "
            "Mertsalov's flywheel on the declared positions is off by " + " and ".join(parts) + ". Run the ODE "
            "steady state (a fraction of a second to a second) when a motor is declared: only it gives the "
            "speed the motor really settles at.")


def methods_figure(study: dict[str, MethodsResult], path: Path | None) -> None:
    """The crank speed |omega| (rad/s) over the cycle by each method, one panel per scheme, table
    positions numbered along the top."""
    from linkage.report.diagrams import number_positions, style_angle_axis
    from linkage.report.style import CURVE_COLOURS, FONT, SMALL
    from linkage.report.words import describe_column

    fig = _figure(7.4)
    axes = fig.subplots(len(study), 1, squeeze=False)[:, 0]
    for ax, (name, res) in zip(axes, study.items()):
        mech = linkage.load(name)
        fine_phi = np.arange(res.fine + 1) * 360.0 / res.fine
        table_phi = np.arange(res.n + 1) * 360.0 / res.n
        ax.plot(table_phi, res.speed("course"), "-", marker="o", ms=4 if res.n <= 40 else 2.5, mfc="white",
                color=CURVE_COLOURS[0], lw=1.4, label="Mertsalov's course method (values at the table positions)")
        ax.plot(fine_phi, np.abs(res.laws["exact"].omega), "-", color=CURVE_COLOURS[1], lw=1.8,
                label="exact energy method, with its flywheel")
        ax.plot(fine_phi, np.abs(res.laws["ode_exact"].omega), "--", color=CURVE_COLOURS[2], lw=1.6,
                label="equation of motion, steady state, with the exact flywheel")
        ax.plot(fine_phi, np.abs(res.laws["ode_course"].omega), ":", color=CURVE_COLOURS[3], lw=1.8,
                label="equation of motion, steady state, with the course method's flywheel")
        wm = abs(dynamics_of(mech).mean_speed)
        ax.axhline(wm, color="0.3", lw=0.9, ls="-.", label="declared mean speed")
        style_angle_axis(ax, table_phi)
        ax.set_ylabel("crank speed |ω|, rad/s", fontsize=FONT)
        ax.set_title(_nice(name), fontsize=SMALL + 1, loc="left")
        number_positions(ax, table_phi, np.arange(1, res.n + 2))
        ax.set_xlabel(describe_column("phi_deg", mech).axis, fontsize=FONT)
    _legend_below(fig, axes, ncols=1)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# 4. the tolerance of solve_ivp
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ToleranceRow:
    """The ODE steady state at one relative tolerance: ``error`` is ``max |w - w_ref| / w_m`` over
    the table positions, ``moment_error`` the relative error of the cycle-mean driving moment,
    ``seconds`` the wall time (s)."""

    scheme: str
    rtol: float
    error: float
    moment_error: float
    seconds: float


def tolerance_study(names: Sequence[str], tolerances: Sequence[float], reference_rtol: float,
                    repeat: int = 1) -> dict[str, dict[str, Any]]:
    """Per scheme: the steady state (with the exact method's flywheel) at each of ``tolerances``
    against the one at ``reference_rtol``."""
    out = {}
    for name in names:
        mech = linkage.load(name)
        constant = exact_method(mech).constant_inertia
        ref_seconds, ref = best_time(steady_state, mech, constant_inertia=constant, rtol=reference_rtol, repeat=1)
        wm = abs(ref.details["mean_speed"])
        rows = []
        for rtol in tolerances:
            seconds, law = best_time(steady_state, mech, constant_inertia=constant, rtol=rtol, repeat=repeat)
            rows.append(ToleranceRow(name, rtol, float(np.max(np.abs(law.omega - ref.omega)) / wm),
                                     relative(law.driving_moment, ref.driving_moment), seconds))
        out[name] = {"rows": rows, "reference_rtol": reference_rtol, "reference_seconds": ref_seconds,
                     "motor": dynamics_of(mech).motor is not None}
    return out


def tolerance_lines(study: dict[str, dict[str, Any]], image: str) -> list[str]:
    """The markdown of the tolerances study (:func:`tolerance_study`); ``image``: the picture's path."""
    names = list(study)
    ref = next(iter(study.values()))["reference_rtol"]
    lines = ["## 4. Tolerance of the ODE integration", "",
             ("`steady_state(mech, constant_inertia=<exact flywheel>, rtol=...)`: error of the steady-state speed "
             f"(largest over the table positions, relative to the mean speed) and of the cycle-mean driving "
             f"moment against the same at rtol = {ref:g}, and the wall time."), ""]
    header = ["rtol"] + [f"{col} {name}" for name in names for col in ("speed error", "M_d error", "time (ms)")]
    rows = []
    for k, rtol in enumerate(r.rtol for r in study[names[0]]["rows"]):
        row = [f"{rtol:g}"]
        for name in names:
            r = study[name]["rows"][k]
            moment = f"{abs(r.moment_error):.1e}" if study[name]["motor"] else "—"
            row += [f"{r.error:.1e}", moment, _ms(r.seconds)]
        rows.append(row)
    rows.append([f"{ref:g} (reference)"] + [x for name in names
                                           for x in ("0", "0" if study[name]["motor"] else "—",
                                                     _ms(study[name]["reference_seconds"]))])
    lines += _table(header, rows)
    lines += ["", ("Without a motor the steady state is one integrated cycle at the balancing moment (so M_d has "
                   "no error: —), and the "
                  "integrator's largest step (2π/90) rather than rtol limits the error at loose tolerances; with "
                  "a motor the shooting integrates several cycles per iteration and the error is erratic (the "
                  "reduced moment is linear between 720 points per turn, which the step control meets at "
                  "every corner)."), "", tolerance_recommendation(study), "", f"Plot: `{image}`", ""]
    return lines


def tolerance_recommendation(study: dict[str, dict[str, Any]]) -> str:
    """One sentence: the loosest rtol from which on the steady speed is within 1e-6 of the mean speed."""
    parts = []
    for name, entry in study.items():
        rows = entry["rows"]
        good = [r for r in rows if all(s.error <= 1e-6 for s in rows if s.rtol <= r.rtol)]
        if good:
            r = good[0]
            parts.append(f"rtol = {r.rtol:g} for {name} ({_ms(r.seconds)} ms against "
                         f"{_ms(entry['reference_seconds'])} ms at {entry['reference_rtol']:g})")
    return ("**Recommendation.** For the steady speed to 1e-6 of the mean speed use " + "; ".join(parts)
            + "; the default rtol = 1e-9 is safely tighter than a course or design study needs.")


def tolerance_figure(study: dict[str, dict[str, Any]], path: Path | None) -> None:
    """Speed error and wall time of the steady state against rtol (log-log), one curve per scheme."""
    from linkage.report.style import CURVE_COLOURS, MARKERS

    fig = _figure(4.4)
    err_ax, time_ax = fig.subplots(1, 2)
    for k, (name, entry) in enumerate(study.items()):
        rtol = np.array([r.rtol for r in entry["rows"]])
        style = {"marker": MARKERS[k], "color": CURVE_COLOURS[k], "mfc": "white", "mew": 1.3, "lw": 1.6}
        x, y = _nonzero(rtol, [r.error for r in entry["rows"]])
        err_ax.plot(x, y, "-", label=f"{_nice(name)}" + (" (induction motor)" if entry["motor"] else
                                                         " (constant moment)"), **style)
        time_ax.plot(rtol, [r.seconds * 1e3 for r in entry["rows"]], "-", **style)
    rtol = np.array([r.rtol for r in next(iter(study.values()))["rows"]])
    err_ax.plot(rtol, rtol, ":", color="0.45", lw=1.1, label="error = rtol")
    _loglog(err_ax, "relative tolerance rtol", "largest speed error / mean speed")
    _loglog(time_ax, "relative tolerance rtol", "wall time of the steady state, ms")
    for ax in (err_ax, time_ax):
        ax.set_xticks(rtol, [f"$10^{{{round(math.log10(r))}}}$" for r in rtol])
        ax.invert_xaxis()
    _legend_below(fig, [err_ax, time_ax], ncols=2)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# 5. closed form vs Newton's method
# ----------------------------------------------------------------------------------------------


def _row_scale(group) -> np.ndarray:
    """The factor of each row of ``group.residual`` over the same row of ``group.jacobians``
    (prismatic angle rows are scaled to metres by the mechanism's size), ``(m,)``."""
    return np.concatenate([np.asarray(j.row_scale(group.size), dtype=float) for j in group.joints])


def _stack(poses: dict[str, np.ndarray], links: Sequence[str]) -> np.ndarray:
    return np.concatenate([poses[k] for k in links], axis=1)


def _split(q: np.ndarray, links: Sequence[str]) -> dict[str, np.ndarray]:
    return {k: q[:, 3 * i: 3 * i + 3] for i, k in enumerate(links)}


def newton_solve(group: Group, known: dict[str, np.ndarray], start: dict[str, np.ndarray], *, tol: float = 1e-12,
                 max_iterations: int = 30) -> tuple[dict[str, np.ndarray], np.ndarray, list[float]]:
    """The group's poses by Newton's method on its constraint equations ``Phi(q) = 0``.

    Parameters
    ----------
    group : assur.Group
        A bound group (``linkage.structure_of(mech).groups``).
    known : dict of link -> ndarray (N, 3)
        Poses of the links the group hangs on.
    start : dict of link -> ndarray (N, 3)
        Starting poses of the group's links.
    tol : float
        A position has converged when its last Newton step is at most ``tol`` (lengths relative
        to the mechanism's size, angles in rad); with quadratic convergence its error is then at
        round-off.
    max_iterations : int

    Returns
    -------
    poses : dict of link -> ndarray (N, 3)
        The group's poses (angles as the iteration leaves them: compare them modulo 2 pi).
    iterations : ndarray (N,) of int
        Newton steps taken per position.
    history : list of float
        The largest constraint residual over the positions (relative to the mechanism's size)
        before each step and after the last.

    Raises
    ------
    linkage.AssemblyError
        When a position has not converged in ``max_iterations`` steps.
    """
    links = group.links
    q = _stack(start, links).astype(float)
    n = len(q)
    scale = _row_scale(group)
    per_unknown = np.tile([group.size, group.size, 1.0], len(links))
    active = np.ones(n, bool)
    iterations = np.zeros(n, int)
    history = []
    for _ in range(max_iterations):
        trial = {**known, **_split(q, links)}
        residual = group.residual(trial)
        history.append(float(np.max(np.abs(residual))) / group.size)
        if not active.any():
            return _split(q, links), iterations, history
        sub = {k: v[active] for k, v in trial.items()}
        jacobian = group.jacobians(sub)[0] * scale[None, :, None]
        step = np.linalg.solve(jacobian, residual[active][..., None])[..., 0]
        q[active] -= step
        iterations[active] += 1
        done = np.max(np.abs(step) / per_unknown, axis=1) <= tol
        active[np.flatnonzero(active)[done]] = False
    if active.any():
        left = np.flatnonzero(active)
        raise AssemblyError(f"{group!r}: Newton's method did not converge at {len(left)} of {n} positions (the "
                            f"first is position index {left[0]}) in {max_iterations} steps")
    trial = {**known, **_split(q, links)}
    history.append(float(np.max(np.abs(group.residual(trial)))) / group.size)
    return _split(q, links), iterations, history


def newton_continuation(group: Group, known: dict[str, np.ndarray], first: dict[str, np.ndarray], *,
                        tol: float = 1e-12) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Newton's method position by position along the input angle, each started from the solution
    at the previous position (the first from ``first``, poses ``(1, 3)``): the poses ``(N, 3)``
    and the Newton steps per position ``(N,)``."""
    n = len(next(iter(known.values())))
    out = {k: np.empty((n, 3)) for k in group.links}
    iterations = np.zeros(n, int)
    start = first
    for i in range(n):
        here = {k: v[i: i + 1] for k, v in known.items()}
        solved, steps, _ = newton_solve(group, here, start, tol=tol)
        for k in group.links:
            out[k][i] = solved[k][0]
        iterations[i] = steps[0]
        start = solved
    return out, iterations


def pose_error(poses: dict[str, np.ndarray], reference: dict[str, np.ndarray], size: float) -> float:
    """The largest difference of two sets of poses: positions relative to ``size``, angles in rad
    (modulo 2 pi)."""
    worst = 0.0
    for k, ref in reference.items():
        d = poses[k] - ref
        worst = max(worst, float(np.max(np.abs(d[:, :2]))) / size,
                    float(np.max(np.abs(np.angle(np.exp(1j * d[:, 2]))))))
    return worst


def newton_schemes() -> dict[str, tuple[str, int]]:
    """Each dyad kind of the shipped schemes -> (scheme, index of the group): the scheme with the
    fewest groups, plain kinematic schemes (no ``[dynamics]``) first, then by name."""
    candidates = []
    for name in linkage.shipped_schemes():
        mech = linkage.load(name)
        groups = linkage.structure_of(mech).groups
        has_dynamics = "dynamics" in mech.extra and mech.extra.get("dynamics") is not None
        if len(mech.inputs) > 1:
            continue      # the table compares one input's mechanisms
        for i, g in enumerate(groups):
            if isinstance(g, Dyad):
                candidates.append((g.kind, has_dynamics, len(groups), name, i))
    out: dict[str, tuple[str, int]] = {}
    for kind, _, _, name, i in sorted(candidates):
        out.setdefault(kind, (name, i))
    return out


@dataclass(frozen=True)
class NewtonResult:
    """Closed form vs Newton's method for one group over ``positions`` input angles.

    Times are per position (s): ``closed`` the library's closed form (``closed_call``: the call
    ``linkage.analyze`` makes, with its checks, vectorised over the positions), ``batch`` Newton's method vectorised over the
    positions from a perturbed closed-form solution, ``continuation`` Newton's method position by
    position from the previous solution. Errors are the largest differences from the closed form
    (lengths relative to the mechanism's size, angles in rad); iterations the largest (batch) and
    mean (continuation) number of Newton steps; ``history`` the batch's residuals per step.
    """

    scheme: str
    group: str
    kind: str
    positions: int
    closed: float
    batch: float
    continuation: float
    batch_error: float
    continuation_error: float
    batch_iterations: int
    continuation_iterations: float
    history: list
    closed_call: str = "group.position"


def closed_form_call(group) -> tuple[str, Callable[..., Any]]:
    """The closed form as ``linkage.analyze`` calls it: ``group.solve`` for positions only where the
    group has it (a kind's fast path), else ``group.position``; its name and ``f(known, branch)``."""
    if callable(getattr(group, "solve", None)):
        return "group.solve", lambda known, branch: group.solve(known, branch=branch)
    return "group.position", group.position


def _closed_form(group, known, reference, repeat) -> float:
    """The closed form's time per call (s) on the branch that reproduces the analysed motion."""
    _, call = closed_form_call(group)
    for branch in group.branches:
        if pose_error(call(known, branch).poses, reference, group.size) < 1e-9:
            seconds, _ = best_time(call, known, branch, repeat=repeat)
            return seconds
    raise AssemblyError(f"{group!r}: no closed-form branch reproduces the analysed motion")


def newton_group(name: str, index: int, positions: int = NEWTON_POSITIONS, perturbation: float = 0.01,
                 repeat: int = 3, seed: int = 1) -> NewtonResult:
    """Closed form vs Newton's method for group ``index`` of scheme ``name`` (:class:`NewtonResult`).

    The batch starts from the closed-form poses moved by a random ``perturbation`` (lengths in
    units of the mechanism's size, angles in rad); the continuation starts its first position the
    same way."""
    mech = linkage.load(name)
    group = linkage.structure_of(mech).groups[index]
    phi = linkage.table_angles(mech, positions)[:-1] if mech.input_range is None else linkage.table_angles(
        mech, positions)
    motion = linkage.analyze(mech, phi, order=0)
    known = {k: motion.poses[k] for k in group.known_links}
    reference = {k: motion.poses[k] for k in group.links}
    n = len(phi)
    closed = _closed_form(group, known, reference, repeat)
    rng = np.random.default_rng(seed)
    shift = np.tile([group.size, group.size, 1.0], len(group.links)) * perturbation
    start = _split(_stack(reference, group.links) + shift * rng.uniform(-1, 1, (n, 3 * len(group.links))),
                   group.links)
    batch, (solved, steps, history) = best_time(newton_solve, group, known, start, repeat=repeat)
    first = {k: v[:1] for k, v in start.items()}
    cont, (followed, cont_steps) = best_time(newton_continuation, group, known, first, repeat=1)
    return NewtonResult(name, repr(group), group.kind, n, closed / n, batch / n, cont / n,
                        pose_error(solved, reference, group.size), pose_error(followed, reference, group.size),
                        int(steps.max()), float(cont_steps.mean()), history, closed_form_call(group)[0])


def newton_study(repeat: int = 3) -> list[NewtonResult]:
    """:func:`newton_group` for one group of each dyad kind of the shipped schemes (:func:`newton_schemes`)."""
    return [newton_group(name, i, repeat=repeat) for _, (name, i) in sorted(newton_schemes().items())]


def newton_lines(results: Sequence[NewtonResult], image: str) -> list[str]:
    """The markdown of the Newton study (:func:`newton_study`); ``image``: the picture's path."""
    call = ", ".join(sorted({r.closed_call for r in results}))
    lines = ["## 5. Closed form vs Newton's method on the same group", "",
             (f"Each dyad kind of the shipped schemes at {NEWTON_POSITIONS} positions of a turn (of the stroke for a "
             "slide input). Closed form: the "
             f"library's `{call}` as `linkage.analyze` calls it (positions only, vectorised, with its closure "
             "and conditioning checks). Newton: "
             "`Φ_q Δq = −Φ` on the group's constraint equations until the step is below 1e-12 (of the "
             "mechanism's size, or rad), from the closed-form solution moved by up to 1 % of the size and "
             "0.01 rad (batch, vectorised over the positions) or from the previous position's solution "
             "(continuation, one position at a time). Errors: the largest difference from the closed form "
             "(lengths relative to the size; angles in rad)."), ""]
    rows = [[r.kind, f"{r.scheme} {r.group}", f"{r.closed * 1e6:.2g}", f"{r.batch * 1e6:.2g}",
             f"{r.batch_iterations}", f"{r.batch_error:.1e}", f"{r.continuation * 1e6:.3g}",
             f"{r.continuation_iterations:.1f}", f"{r.continuation_error:.1e}"] for r in results]
    lines += _table(["kind", "group", "closed form (µs/position)", "Newton batch (µs/position)", "batch steps (max)",
                     "batch error", "Newton continuation (µs/position)", "continuation steps (mean)",
                     "continuation error"], rows)
    lines += ["", newton_recommendation(results), "", f"Plot: `{image}`", ""]
    return lines


def newton_recommendation(results: Sequence[NewtonResult]) -> str:
    batch = [r.batch / r.closed for r in results]
    cont = [r.continuation / r.closed for r in results]
    worst = max(max(r.batch_error, r.continuation_error) for r in results)
    return (f"**Recommendation.** Keep the closed forms: Newton's method reaches the same poses (to {worst:.0e}) "
            f"but costs {min(batch):.1f}–{max(batch):.1f} times as much per position vectorised and "
            f"{min(cont):.0f}–{max(cont):.0f} times as much by continuation; use it only for a group that has no "
            "closed form, and then vectorised from a predicted start rather than position by position.")


def newton_figure(results: Sequence[NewtonResult], path: Path | None) -> None:
    """Newton's residual per step for each kind, and the time per position of the closed form and of
    Newton's method (batch, continuation)."""
    from linkage.report.style import CURVE_COLOURS, FONT, MARKERS, SMALL

    fig = _figure(4.6)
    conv_ax, time_ax = fig.subplots(1, 2)
    for k, r in enumerate(results):
        h = np.maximum(np.array(r.history), 1e-18)
        conv_ax.plot(np.arange(len(h)), h, "-", marker=MARKERS[k % len(MARKERS)], color=CURVE_COLOURS[k],
                     mfc="white", mew=1.3, lw=1.5, label=f"{r.kind} ({_nice(r.scheme)})")
    conv_ax.set_yscale("log")
    conv_ax.set_xlabel("Newton step", fontsize=FONT)
    conv_ax.set_ylabel("largest constraint residual / size", fontsize=FONT)
    conv_ax.axhline(EPS, color="0.45", ls=":", lw=1.0, label="machine epsilon")
    conv_ax.tick_params(labelsize=SMALL)
    conv_ax.grid(True, alpha=0.35)
    conv_ax.set_title("convergence from a perturbed start", fontsize=SMALL + 1)
    x = np.arange(len(results))
    width = 0.27
    bars = (("closed", "closed form"), ("batch", "Newton, vectorised, perturbed start"),
            ("continuation", "Newton, continuation along φ"))
    for j, (key, words) in enumerate(bars):
        time_ax.bar(x + (j - 1) * width, [getattr(r, key) * 1e6 for r in results], width, color=CURVE_COLOURS[j + 3],
                    label=words)
    time_ax.set_yscale("log")
    time_ax.set_ylim(bottom=0.2 * min(r.closed for r in results) * 1e6)
    time_ax.set_title("cost", fontsize=SMALL + 1)
    time_ax.set_xticks(x, [r.kind for r in results])
    time_ax.set_xlabel("dyad kind", fontsize=FONT)
    time_ax.set_ylabel("time per position, µs", fontsize=FONT)
    time_ax.tick_params(labelsize=SMALL)
    time_ax.grid(True, axis="y", alpha=0.35)
    _legend_below(fig, [conv_ax, time_ax], ncols=2)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# 6. exact analogs vs finite differences
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AnalogRow:
    """The largest differences of the exact first and second analogs of every column of a
    scheme's table from 5-point finite differences with step ``h``, relative to the mechanism's
    size (angles: in rad).

    ``h`` is in rad of a crank; for a slide input it is in rad of the equivalent turn (the stroke
    is one turn, :class:`InputSweep`): the step is then ``h * scale`` m and the analogs are taken
    per rad of that turn, so the rows of every scheme compare.
    """

    scheme: str
    h: float
    first: float
    second: float
    slide: bool = False


@dataclass(frozen=True)
class InputSweep:
    """The input values a study runs over and the unit of its steps.

    ``values`` (rad for a crank, m for a slide), ``scale`` the input's units per rad of a turn:
    1 for a crank; for a slide, its declared stroke (``mech.input_range``, m) over 2 pi, so that
    a step ``h`` (rad) moves the slide by ``h * scale`` m and the stroke is one turn.
    """

    values: np.ndarray
    scale: float
    slide: bool
    words: str


def input_sweep(mech: linkage.Mechanism, positions: int, margin: float = 0.0) -> InputSweep:
    """``positions`` values of the input over a turn of a crank (from 0.1 rad), over its declared
    input range, or over a slide's declared stroke (m), inside the range or stroke by ``margin``
    (rad of a turn: ``margin * scale`` m for a slide); :class:`InputSweep`."""
    if mech.input_range is None:
        return InputSweep(np.linspace(0.1, 0.1 + 2 * np.pi, positions, endpoint=False), 1.0, False, "a turn")
    a, b = sorted(float(v) for v in mech.input_range)
    slide = not mech.coordinate.is_angle
    scale = (b - a) / (2 * np.pi) if slide else 1.0
    if b - a <= 2 * margin * scale:
        raise SchemeError(f"mechanism '{mech.name}': its input range [{a:.6g}, {b:.6g}] is narrower than twice the "
                          f"finite-difference margin {margin * scale:.6g}")
    words = f"the stroke {a:.4g}–{b:.4g} m" if slide else f"the range {a:.4g}–{b:.4g} rad"
    return InputSweep(np.linspace(a + margin * scale, b - margin * scale, positions), scale, slide, words)


def _finite_differences(mech: linkage.Mechanism, sweep: InputSweep, h: float,
                        exact: dict[str, np.ndarray]) -> tuple[float, float]:
    """The largest differences of the first and second analogs (per rad of the sweep's turn) from
    5-point finite differences with step ``h`` (rad of the turn), relative to the size."""
    step = h * sweep.scale                             # rad, or m for a slide
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        shifted = {k: linkage.analyze(mech, sweep.values + k * step, order=0).columns() for k in (-2, -1, 1, 2)}
    e1 = e2 = 0.0
    for col, value in exact.items():
        if col.endswith("'") or col in ("i", "phi_deg") or col + "'" not in exact:
            continue
        f = {k: shifted[k][col] for k in shifted}
        if col.endswith("theta"):
            f = {k: value + np.angle(np.exp(1j * (v - value))) for k, v in f.items()}
        d1 = (f[-2] - 8 * f[-1] + 8 * f[1] - f[2]) / (12 * step)
        d2 = (-f[-2] + 16 * f[-1] - 30 * value + 16 * f[1] - f[2]) / (12 * step * step)
        size = 1.0 if col.endswith("theta") else mech.size
        e1 = max(e1, float(np.max(np.abs(d1 - exact[col + "'"]))) * sweep.scale / size)
        e2 = max(e2, float(np.max(np.abs(d2 - exact[col + "''"]))) * sweep.scale ** 2 / size)
    return e1, e2


def analog_study(names: Sequence[str] | None = None, steps: Sequence[float] = STEPS,
                 positions: int = 36) -> list[AnalogRow]:
    """:class:`AnalogRow` for every scheme of ``names`` (default: the shipped ones) and step of ``steps``,
    at ``positions`` values of the input (:func:`input_sweep`: a turn of a crank, its input range,
    or a slide's stroke, inside the range or stroke by 3 of the largest steps)."""
    rows = []
    for name in names or linkage.shipped_schemes():
        mech = linkage.load(name)
        sweep = input_sweep(mech, positions, margin=3 * max(steps))
        with warnings.catch_warnings():  # the positions are far apart and analysed each on its own: the
            warnings.simplefilter("ignore", BranchWarning)  # check of continuity between them does not apply
            exact = linkage.analyze(mech, sweep.values).columns()
        for h in steps:
            rows.append(AnalogRow(name, h, *_finite_differences(mech, sweep, h, exact), slide=sweep.slide))
    return rows


def analog_lines(rows: Sequence[AnalogRow], image: str, h: float = 1e-3) -> list[str]:
    """The markdown of the analogs study (:func:`analog_study`); ``image``: the picture's path."""
    slides = [name for name in dict.fromkeys(r.scheme for r in rows if r.slide)]
    lines = ["## 6. Exact analogs vs 5-point finite differences", "",
             ("Largest difference over 36 positions and every column of `linkage analyze` (points, angles, "
             "slides), relative to the mechanism's size (angles in rad), at the step h = 1e-3 rad and at the "
             "step where it is smallest. Every shipped scheme: a crank over a turn (or its declared range), "
             + (f"a slide input ({', '.join(slides)}; marked *slide*) over its declared stroke in metres: the "
                "stroke counts as one turn, so its step is h × stroke / 2π m and its analogs are taken per rad "
                "of that turn (the rows compare)." if slides else "a slide input over its declared stroke.")),
             ""]
    table = []
    for name in dict.fromkeys(r.scheme for r in rows):
        mine = [r for r in rows if r.scheme == name]
        at = min(mine, key=lambda r: abs(math.log(r.h / h)))
        best1, best2 = min(mine, key=lambda r: r.first), min(mine, key=lambda r: r.second)
        table.append([name + (" (*slide*)" if mine[0].slide else ""), f"{at.first:.1e}", f"{at.second:.1e}",
                      f"{best1.first:.1e} (h = {best1.h:g})", f"{best2.second:.1e} (h = {best2.h:g})"])
    lines += _table(["scheme", "q' at h = 1e-3", "q'' at h = 1e-3", "q' smallest", "q'' smallest"], table)
    lines += ["", ("The differences follow the finite differences' own error, truncation ∝ h⁴ for large h and "
                  "rounding ∝ ε/h (first) and ε/h² (second) for small h: none of it is an error of the exact analogs."),
              "", analog_recommendation(rows), "", f"Plot: `{image}`", ""]
    return lines


def analog_recommendation(rows: Sequence[AnalogRow]) -> str:
    """One sentence: the step that makes the largest difference over the schemes smallest, per order."""
    steps = sorted({r.h for r in rows})
    worst = {key: [max(getattr(r, key) for r in rows if r.h == h) for h in steps] for key in ("first", "second")}
    best = {key: int(np.argmin(values)) for key, values in worst.items()}
    return ("**Recommendation.** Use the exact analogs; a finite-difference check of your own mechanism should "
            f"use h ≈ {steps[best['first']]:g} rad for first and h ≈ {steps[best['second']]:g} rad for second "
            f"analogs and expect agreement to about {worst['first'][best['first']]:.0e} and "
            f"{worst['second'][best['second']]:.0e} of the size, not better.")


def analog_figure(rows: Sequence[AnalogRow], path: Path | None) -> None:
    """The largest difference over the schemes against the step h (log-log), with the truncation and
    rounding slopes."""
    from linkage.report.style import CURVE_COLOURS, MARKERS

    fig = _figure(4.6)
    ax = fig.add_subplot()
    h = np.array(sorted({r.h for r in rows}))
    for j, key, words in ((0, "first", "first analogs q' (largest over the shipped schemes)"),
                          (1, "second", "second analogs q'' (largest over the shipped schemes)")):
        worst = [max(getattr(r, key) for r in rows if r.h == step) for step in h]
        ax.plot(h, worst, "-", marker=MARKERS[j], color=CURVE_COLOURS[j], mfc="white", mew=1.3, lw=1.6, label=words)
    first = [max(r.first for r in rows if r.h == step) for step in h]
    _slope(ax, h, (h[-1], first[-1]), 4, "truncation ∝ $h^4$", ":")
    _slope(ax, h, (h[0], 2 * EPS / h[0]), -1, "rounding ∝ ε/h", "-.")
    _slope(ax, h, (h[0], 2 * EPS / h[0] ** 2), -2, "rounding ∝ ε/$h^2$", "--")
    _loglog(ax, "finite-difference step h, rad", "largest difference / size")
    ax.set_ylim(1e-14, 1e0)
    _legend_below(fig, [ax], ncols=2)
    _save(fig, path)


# ----------------------------------------------------------------------------------------------
# the run
# ----------------------------------------------------------------------------------------------


def _image(images: Path | None, study: str) -> tuple[Path | None, str]:
    """The picture's path (None: draw nothing) and the name the markdown gives it."""
    name = f"docs/images/trade_{study}.png"
    return (None if images is None else images / f"trade_{study}.png"), name


def run(quick: bool = True, *, images: Path | None = IMAGES) -> list[str]:
    """Every study: the markdown lines of their tables and recommendations.

    Parameters
    ----------
    quick : bool
        Fewer repeats for the times and a looser reference for the ODE tolerances (about 40 s on a
        2-core machine instead of about a minute).
    images : Path or None
        Folder of the pictures ``trade_<study>.png`` (default ``docs/images``); None draws none.
    """
    import matplotlib

    matplotlib.use("Agg")
    repeat = 3 if quick else 7
    t0 = time.perf_counter()
    names = dynamics_schemes()
    lines = ["# The speed/accuracy trade", "",
             (f"Written by `benchmarks/trade.py` ({'--quick' if quick else 'full run'}) on {time.strftime('%Y-%m-%d')}; "
             f"numpy {np.__version__}. Schemes with [dynamics]: {', '.join(names)}. What the figures mean: "
             "`docs/speed_accuracy.md`."), ""]
    path, name = _image(images, "positions")
    study = positions_study(names, repeat=repeat)
    positions_figure(study, path)
    lines += positions_lines(study, name)
    path, name = _image(images, "quadrature")
    quad = quadrature_study(names)
    quadrature_figure(quad, path)
    lines += quadrature_lines(quad, name)
    path, name = _image(images, "methods")
    methods = methods_study(names, repeat=repeat)
    methods_figure(methods, path)
    lines += methods_lines(methods, name)
    path, name = _image(images, "tolerances")
    tol = tolerance_study(names, TOLERANCES[quick], REFERENCE_RTOL[quick], repeat=2 if quick else 3)
    tolerance_figure(tol, path)
    lines += tolerance_lines(tol, name)
    path, name = _image(images, "newton")
    newton = newton_study(repeat=repeat)
    newton_figure(newton, path)
    lines += newton_lines(newton, name)
    path, name = _image(images, "analogs")
    analogs = analog_study()
    analog_figure(analogs, path)
    lines += analog_lines(analogs, name)
    lines += [f"All studies took {time.perf_counter() - t0:.0f} s.", ""]
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """``python benchmarks/trade.py [--quick] [--out FILE] [--no-images]``."""
    parser = argparse.ArgumentParser(description="Measure the speed/accuracy trade of the library (tables in "
                                                 "markdown, pictures docs/images/trade_*.png).")
    parser.add_argument("--quick", action="store_true", help="fewer repeats, looser ODE reference (about 40 s)")
    parser.add_argument("--out", type=Path, help="write the markdown to this file instead of printing it")
    parser.add_argument("--no-images", action="store_true", help="draw no pictures")
    args = parser.parse_args(argv)
    lines = run(args.quick, images=None if args.no_images else IMAGES)
    text = "\n".join(lines) + "\n"
    if args.out:
        args.out.write_text(text, encoding="utf-8")
        print(f"written {args.out}")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
