"""The figures behind the status-OK guarantee, written to ``benchmarks/results_guarantee.md``.

Run: ``python benchmarks/bench_guarantee.py`` (about 20 s; needs mpmath, in the test extra).

For a crank followed by one dyad of each kind (and a two-dyad chain), the input angle is moved
toward the dyad's singular position (toggle, parallel guides) in steps of a decade. At each
angle the library's analogs -- computed with the singular flag switched off, so the raw error is
seen -- are compared with a 50-digit mpmath reference (``tests/_edge_mechanisms.py``). The table
gives the group's conditioning r, the largest relative error of the first and second analogs,
the round-off factor ``err1 * r**2 / eps`` of the model ``err1 <= ROUNDOFF_FACTOR * eps / r**2``,
and the status the library gives with the flag on.
"""

from __future__ import annotations

import sys
from datetime import date
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import assur.base  # noqa: E402
import linkage  # noqa: E402
from _edge_mechanisms import CASES, CHAIN, reference, relative_errors  # noqa: E402

EPS = np.finfo(float).eps


def sweep(case, lines, factors):
    mech = linkage.loads(case.toml)
    lines += [f"## {case.kind}", "",
              "| distance (rad) | conditioning r | rel. error q' | rel. error q'' | err·r²/eps | status |",
              "|---|---|---|---|---|---|"]
    for k in range(1, 17):
        phi = case.singular_phi + case.side * 10.0**-k
        status = linkage.analyze(mech, [phi], on_failure="mask").status[0]
        saved = assur.base.ANALOG_TOL
        assur.base.ANALOG_TOL = np.inf          # measure the raw error, flag off
        try:
            motion = linkage.analyze(mech, [phi], on_failure="mask")
        finally:
            assur.base.ANALOG_TOL = saved
        if motion.status[0] != 0:
            lines.append(f"| 1e-{k:02d} | — | — | — | — | {status} |")
            continue
        r = min(float(v[0]) for v in motion.conditioning.values())
        e1, e2 = relative_errors(motion, reference(case, phi))
        factor = e1 * r**2 / EPS
        factors.append(factor)
        lines.append(f"| 1e-{k:02d} | {r:.2e} | {e1:.1e} | {e2:.1e} | {factor:.2f} | {status} |")
    lines.append("")


def main() -> None:
    lines = ["# The status-OK guarantee: measured errors toward singular positions", "",
             f"Written by `benchmarks/bench_guarantee.py` on {date.today()}; numpy {np.__version__}.", "",
             "Relative errors are against a 50-digit mpmath reference, relative to the largest analog "
             "of the group and its input (q'' errors relative to the largest q''). The status column is "
             "what `analyze` reports (0 OK, -1 cannot assemble, -2 singular): where it is 0 the error "
             f"must be at most ANALOG_TOL = {assur.base.ANALOG_TOL:g} (q') and ten times that (q'').", ""]
    factors: list[float] = []
    for case in [*CASES.values(), CHAIN]:
        sweep(case, lines, factors)
    lines[6:6] = [f"Largest round-off factor err·r²/eps measured over all kinds: **{max(factors):.2f}** "
                  f"(the library uses ROUNDOFF_FACTOR = {assur.base.ROUNDOFF_FACTOR:g}, so a single "
                  f"group is flagged below r = {assur.base.SINGULAR_TOL:.2e}).", ""]
    out = ROOT / "benchmarks" / "results_guarantee.md"
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    print(f"written to {out}")


if __name__ == "__main__":
    main()
