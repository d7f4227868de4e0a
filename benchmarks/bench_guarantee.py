"""The figures behind the status-OK guarantee, written to ``benchmarks/results_guarantee.md``.

Run: ``python benchmarks/bench_guarantee.py`` (about a minute; needs mpmath, in the test extra).

Singular positions: for a crank followed by one dyad of each kind (and a two-dyad chain), the
input angle is moved toward the dyad's singular position (toggle, parallel guides) in steps of a
decade. At each angle the library's analogs -- computed with the singular flag switched off, so
the raw error is seen -- are compared with a 50-digit mpmath reference (``tests/_edge_mechanisms.py``).
The table gives the group's conditioning r, the largest relative error of the first and second
analogs, the round-off factor ``err1 * r**2 / eps`` of the model ``err1 <= ROUNDOFF_FACTOR * eps / r**2``,
and the status the library gives with the flag on.

Change points (and the toggles of four-bars next to one): an isosceles slider-crank (crank = rod,
guide along x and turned), parallelogram four-bars and near-Grashof four-bars are swept toward
the position at 10 distances a decade from 1e-1 to 1e-6 rad, against 50-digit references written
here (mpmath). There the analogs stay bounded while r goes to 0, and the second analogs' error
grows like the first analogs' over r: the table counts the status-OK positions outside the
promise (must be 0) and the flagged ones, and gives the factor ``err2 / (2 A eps / r**3)`` of the
second-analog model (``assur.base.second_analog_excess``; the library uses CHANGE_FACTOR).
"""

from __future__ import annotations

import sys
import warnings
from contextlib import contextmanager
from datetime import date
from pathlib import Path

import mpmath as mp
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import assur.base  # noqa: E402
import assur.dyad  # noqa: E402
import linkage  # noqa: E402
from _edge_mechanisms import CASES, CHAIN, _derivatives, reference, relative_errors  # noqa: E402
from _texts import four_bar_toml, slider_crank_toml  # noqa: E402

EPS = np.finfo(float).eps
mp.mp.dps = 50


@contextmanager
def flag_off():
    """The analogs everywhere they can be solved: the status-OK tolerance set to inf (in
    :mod:`assur.base` and in the dyads' fast path, which imports it)."""
    saved = assur.base.ANALOG_TOL
    assur.base.ANALOG_TOL = assur.dyad.ANALOG_TOL = np.inf
    try:
        yield
    finally:
        assur.base.ANALOG_TOL = assur.dyad.ANALOG_TOL = saved


def sweep(case, lines, factors):
    mech = linkage.loads(case.toml)
    lines += [f"## {case.kind}", "",
              "| distance (rad) | conditioning r | rel. error q' | rel. error q'' | err·r²/eps | status |",
              "|---|---|---|---|---|---|"]
    for k in range(1, 17):
        phi = case.singular_phi + case.side * 10.0**-k
        status = linkage.analyze(mech, [phi], on_failure="mask").status[0]
        with flag_off():
            motion = linkage.analyze(mech, [phi], on_failure="mask")
        if motion.status[0] != 0:
            lines.append(f"| 1e-{k:02d} | — | — | — | — | {status} |")
            continue
        r = min(float(v[0]) for v in motion.conditioning.values())
        e1, e2 = relative_errors(motion, reference(case, phi))
        factor = e1 * r**2 / EPS
        factors.append(factor)
        lines.append(f"| 1e-{k:02d} | {r:.2e} | {e1:.1e} | {e2:.1e} | {factor:.2f} | {status} |")
    lines.append("")


# ----------------------------------------------------------------------------------------------
# change points: the mechanisms and their 50-digit references
# ----------------------------------------------------------------------------------------------
def isosceles(alpha_deg: float):
    """Slider-crank with crank = rod = 1 whose guide through O makes alpha with x, followed
    through its change point (the crank across the guide): the slide s = 2 cos(phi - alpha)."""
    toml = slider_crank_toml(1.0, 1.0, f'from = "O"\ntowards_deg = {alpha_deg!r}\nphi_deg = {alpha_deg + 45!r}\n'
                             'mode = "follow"', name="isosceles_slider_crank")
    toml = toml.replace("angle_deg = 0 }", f"angle_deg = {alpha_deg!r} }}")
    alpha = mp.radians(mp.mpf(alpha_deg))

    def f(phi):
        s = 2 * mp.cos(phi - alpha)
        return {"slide.s": s, "B.x": s * mp.cos(alpha), "B.y": s * mp.sin(alpha), "2.theta": 2 * alpha - phi}

    return toml, (lambda motion, phi: _derivatives(f, phi)), float(np.radians(alpha_deg) + np.pi / 2)


def four_bar(crank, coupler, rocker, ground, mode="follow"):
    """Four-bar O-A-B-C (``tests/_texts.four_bar_toml``); the reference is the circle-intersection
    closed form on the side of A -> C where the library put B."""
    toml = four_bar_toml(crank, coupler, rocker, ground, f'left_of = ["A", "C"]\nphi_deg = 90\nmode = "{mode}"',
                         name=f"four_bar_{crank}_{coupler}_{rocker}_{ground}")
    l1, l2, l3, l0 = (mp.mpf(str(v)) for v in (crank, coupler, rocker, ground))

    def closed_form(sign):
        def f(phi):
            ax, ay = l1 * mp.cos(phi), l1 * mp.sin(phi)
            d = mp.sqrt((l0 - ax) ** 2 + ay**2)
            ex, ey = (l0 - ax) / d, -ay / d
            a = (l2**2 - l3**2 + d**2) / (2 * d)
            h = sign * mp.sqrt(l2**2 - a**2)
            bx, by = ax + a * ex - h * ey, ay + a * ey + h * ex
            return {"B.x": bx, "B.y": by, "2.theta": mp.atan2(by - ay, bx - ax), "3.theta": mp.atan2(by, bx - l0)}
        return f

    def ref(motion, phi):
        bx, by = motion.point("B")[0]
        both = [_derivatives(closed_form(sign), phi) for sign in (1, -1)]
        return min(both, key=lambda q: abs(q["B.x"][0] - bx) + abs(q["B.y"][0] - by))

    return toml, ref


def toggle(crank, coupler, rocker, ground, reach):
    """Input angle (rad, in [0, pi]) where |AC| = reach (a toggle of the RRR dyad)."""
    return float(mp.acos((crank**2 + ground**2 - reach**2) / (2 * crank * ground)))


def change_point_cases():
    """(name, toml, reference, angle of the point, side) of every change-point sweep."""
    out = []
    for alpha in (0.0, 30.0):
        toml, ref, at = isosceles(alpha)
        out += [(f"isosceles slider-crank, guide at {alpha:g}°, side {s:+d}", toml, ref, at, s) for s in (-1, 1)]
    for dims in ((1, 2, 1, 2), (1, 3, 1, 3)):
        toml, ref = four_bar(*dims)
        out += [(f"parallelogram {dims}, φ = {name}, side {side:+d}", toml, ref, at, side)
                for at, name, side in ((np.pi, "180°", -1), (np.pi, "180°", 1), (0.0, "0°", 1))]
    for dims, reach, side in (((1, 2, 1, 2.001), 3.0, -1), ((1, 2, 0.999, 2), 2.999, -1),
                              ((1, 2, 1, 1.999), 1.0, 1), ((1, 2, 1, 2.00001), 3.0, -1)):
        toml, ref = four_bar(*dims, mode="keep")
        out.append((f"non-Grashof {dims}, toggle at |AC| = {reach:g}", toml, ref, toggle(*dims, reach), side))
    for dims in ((1, 2, 1.001, 2), (1, 2, 1.00001, 2)):
        toml, ref = four_bar(*dims, mode="keep")
        out.append((f"Grashof {dims}, toward φ = 180°", toml, ref, np.pi, 1))
    return out


CHANGE_DISTANCES = 10.0 ** -np.arange(1.0, 6.01, 0.1)


def change_sweep(name, toml, ref, at, side, lines, summary):
    """One change-point sweep: a decade table and a summary line over :data:`CHANGE_DISTANCES`."""
    mech = linkage.loads(toml)
    promise1, promise2 = assur.base.ANALOG_TOL, 10 * assur.base.ANALOG_TOL
    rows = []
    for delta in CHANGE_DISTANCES:
        phi = at + side * delta
        status = linkage.analyze(mech, [phi], on_failure="mask").status[0]
        with flag_off():
            motion = linkage.analyze(mech, [phi], on_failure="mask")
        if motion.status[0] != 0:
            rows.append((delta, np.nan, np.nan, np.nan, np.nan, status))
            continue
        r = min(float(v[0]) for v in motion.conditioning.values())
        e1, e2 = relative_errors(motion, ref(motion, phi))
        # the second-analog term of the bound, 2 A (CHANGE_FACTOR eps / r**2) / r, is ten times what
        # it adds to the first analogs' 3 eps / r**2 (one group after the crank: no input error)
        model = 10 * (motion.error_bound[0] - assur.base.ROUNDOFF_FACTOR * EPS / r**2) / assur.base.CHANGE_FACTOR
        # the factor where the model decides (deep inside the flagged zone the analogs it sizes
        # A from are themselves wrong)
        rows.append((delta, r, e1, e2, e2 / model if 0 < model <= 1e-3 else np.nan, status))
    rows = np.array(rows)
    ok = rows[:, 5] == 0
    outside = int(np.sum(ok & ((rows[:, 2] > promise1) | (rows[:, 3] > promise2))))
    flagged = rows[~ok, 0]
    factor = np.nanmax(rows[:, 4])
    summary.append((name, outside, len(flagged), float(flagged.max()) if len(flagged) else 0.0,
                    float(np.nanmax(rows[ok, 3])) if ok.any() else np.nan, float(np.nanmax(rows[:, 3])), factor))
    lines += [f"### {name}", "",
              "| distance (rad) | conditioning r | rel. error q' | rel. error q'' | err2 / (2A·eps/r³) | status |",
              "|---|---|---|---|---|---|"]
    for delta, r, e1, e2, f2, status in rows[::10]:
        cells = "— | — | — | —" if np.isnan(r) else f"{r:.2e} | {e1:.1e} | {e2:.1e} | " + \
            ("—" if np.isnan(f2) else f"{f2:.4f}")
        lines.append(f"| {delta:.0e} | {cells} | {int(status)} |")
    lines.append("")


def main() -> None:
    warnings.simplefilter("ignore")       # BranchWarning where the keep mode passes a change point
    lines = ["# The status-OK guarantee: measured errors toward singular positions and change points", "",
             f"Written by `benchmarks/bench_guarantee.py` on {date.today()}; numpy {np.__version__}.", "",
             "Relative errors are against a 50-digit mpmath reference, relative to the largest analog "
             "of the group and its input (q'' errors relative to the largest q'' or q'). The status column is "
             "what `analyze` reports (0 OK, -1 cannot assemble, -2 singular): where it is 0 the error "
             f"must be at most ANALOG_TOL = {assur.base.ANALOG_TOL:g} (q') and ten times that (q'').", ""]
    factors: list[float] = []
    for case in [*CASES.values(), CHAIN]:
        sweep(case, lines, factors)
    lines[6:6] = [f"Largest round-off factor err·r²/eps measured over all kinds: **{max(factors):.2f}** "
                  f"(the library uses ROUNDOFF_FACTOR = {assur.base.ROUNDOFF_FACTOR:g}, so a single "
                  f"group is flagged below r = {assur.base.SINGULAR_TOL:.2e}).", ""]
    details: list[str] = []
    summary: list[tuple] = []
    for case in change_point_cases():
        change_sweep(*case, details, summary)
    worst = max(s[6] for s in summary)
    lines += ["## Change points and the toggles next to them", "",
              f"{len(CHANGE_DISTANCES)} angles from 1e-1 to 1e-6 rad of each point (10 a decade). "
              "`OK outside` counts the status-OK positions whose error exceeds the promise (must be 0); "
              "`flagged` the positions given status -2, `farthest` the largest distance flagged; "
              "the errors are measured with the flag off; the factor err2 / (2A·eps/r³) where the model "
              "term is at most 1e-3 (deeper, the analogs A is sized from are themselves wrong).", "",
              f"Largest factor err2 / (2A·eps/r³) measured: **{worst:.3f}** (the library uses "
              f"CHANGE_FACTOR = {assur.base.CHANGE_FACTOR:g}).", "",
              "| sweep | OK outside | flagged | farthest flagged (rad) | largest q'' error, OK | largest q'' error, flag off | err2 / (2A·eps/r³) |",
              "|---|---|---|---|---|---|---|"]
    for name, outside, n_flagged, farthest, e2_ok, e2_all, factor in summary:
        lines.append(f"| {name} | {outside} | {n_flagged} | {farthest:.1e} | {e2_ok:.1e} | {e2_all:.1e} | {factor:.4f} |")
    lines += ["", *details]
    out = ROOT / "benchmarks" / "results_guarantee.md"
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    print(f"written to {out}")
    assert all(s[1] == 0 for s in summary), "a status-OK position lies outside the promise"


if __name__ == "__main__":
    main()
