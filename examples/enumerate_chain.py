"""Every R/P assignment of the four-bar's chain, each written as a scheme that runs a full turn.

The chain of ``four_bar`` (crank O-A, coupler A-B, rocker B-C) has three pairs besides the crank's
bearing; each is revolute or prismatic with its guide on either link: 27 assignments, 19 of which
decompose into solvable groups (8 in closed form, 11 solved by Newton's method; the 8 with three
prismatic pairs are rejected). The example writes the schemes of those that run a full turn with
the four-bar's own geometry and the table (stroke, smallest transmission angle, peak balancing
moment at 10 rad/s) into the output folder, prints the table, and draws every written combination
at the position its geometry was taken from (``combinations.png``). It takes about 15 s: loading
each scheme with a group solved by Newton's method traces the group's modes over a turn (hence
``newton=True``; without it those are listed, not searched, in 2-3 s).

Run: ``python examples/enumerate_chain.py [OUTPUT_DIR]`` (default ``out/``).
"""

import math
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import linkage
from linkage.research import COLUMN_UNITS, enumerate_chain
from linkage.report import format_columns
from linkage.report.plots import draw_mechanism

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out") / "four_bar_combinations"
found = enumerate_chain("four_bar", omega=10.0, newton=True)   # newton: search the traced groups too
found.write(out)

columns = found.columns()
notes = columns.pop("note")
print(format_columns(columns, "table", units=COLUMN_UNITS), end="")
for ident, note in zip(columns["id"], notes):
    if note:
        print(f"# {ident}: {note}")
print(f"{len(found.rejected)} assignments rejected, e.g. {found.rejected[0].id}: {found.rejected[0].reason}")

# each scheme written is an ordinary scheme file: load it, analyse it, draw it
running = [c for c in found.combinations if c.full_turn]
ncols = 2
nrows = math.ceil(len(running) / ncols)
fig, axes = plt.subplots(nrows, ncols, figsize=(6.3, 2.9 * nrows), layout="constrained")
for ax, combination in zip(axes.flat, running):
    mech = linkage.load(out / combination.assignment.file_name)
    motion = linkage.analyze(mech, np.radians([combination.reference_deg]))
    stroke = f"{combination.stroke:.4g} {combination.stroke_unit}" if combination.stroke is not None else "none"
    draw_mechanism(motion, 0, ax=ax, labels=["O", "A", "B", "C"],
                   caption=f"{combination.id}: {combination.formula[9:]}\nstroke of {combination.output}: {stroke}")
for ax in list(axes.flat)[len(running):]:
    ax.set_visible(False)
fig.suptitle("The four-bar's chain with revolute (R) and prismatic (P: guide on link n) pairs,\n"
             "each at the crank angle its geometry was taken from", fontsize=10)
fig.savefig(out / "combinations.png", dpi=150)
plt.close(fig)
print(f"written: {out} ({len(running)} schemes, combinations.csv, rejected.csv, combinations.png)")
