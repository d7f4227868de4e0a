"""A five-bar driven by two cranks: the tool point's path and each crank's moment for three gearings.

Loads the shipped ``five_bar_two_input`` (cranks OA and QD, couplers AB and DB meeting at the tool
point B; the second crank turns by a law of the first's angle), replaces the law of crank 4 with
``Mechanism.with_input_laws``, and for each law prints the tool point's travel and the peak
balancing moment on each crank at 10 rad/s, and draws the paths of B into ``OUT/two_inputs.png``
(matplotlib, the ``plot`` extra). Run: ``python examples/two_inputs.py [OUT]``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import linkage
from linkage.kinetostatics.reactions import solve_reactions

mech = linkage.load("five_bar_two_input")
phi = np.radians(np.arange(0.0, 361.0, 2.0))     # a closed turn: the last angle repeats the first
laws = {
    "theta4 = 150 deg - phi (shipped)": linkage.InputLaw(ratio=-1.0, phase=math.radians(150.0)),
    "theta4 = 180 deg - phi (mirrored)": linkage.InputLaw(ratio=-1.0, phase=math.radians(180.0)),
    "theta4 = 90 deg + phi (in step)": linkage.InputLaw(ratio=1.0, phase=math.radians(90.0)),
}
paths = {}
print(f"{'law of crank 4':36s} {'B: x range':>12s} {'y range':>9s} {'max |M_b1|':>11s} {'max |M_b4|':>11s}")
print(f"{'':36s} {'[m]':>12s} {'[m]':>9s} {'[N m]':>11s} {'[N m]':>11s}")
for label, law in laws.items():
    variant = mech.with_input_laws(**{"4": law})
    motion = linkage.analyze(variant, phi, omega=10.0)
    reactions = solve_reactions(motion)
    b = motion.point("B")
    paths[label] = b
    peaks = [np.max(np.abs(reactions.balancing_moments[k])) for k in variant.inputs]
    print(f"{label:36s} {np.ptp(b[:, 0]):12.4f} {np.ptp(b[:, 1]):9.4f} {peaks[0]:11.3f} {peaks[1]:11.3f}")

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("two_inputs_out")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: pip install 'linkage[plot]' to draw the paths")
    raise SystemExit(0)
out.mkdir(parents=True, exist_ok=True)
fig, ax = plt.subplots(figsize=(5.0, 5.6), layout="constrained")
for (label, b), style in zip(paths.items(), ("-", "--", ":")):
    ax.plot(b[:, 0], b[:, 1], style, lw=2, label=label)
frame = np.array([mech.links["0"].points[p] for p in ("O", "Q")])
ax.plot(frame[:, 0], frame[:, 1], "k^", ms=9, label="crank pivots O, Q")
ax.set(xlabel="x, m", ylabel="y, m", title="Five-bar with two cranks: path of the tool point B\nfor three laws of crank 4")
ax.set_aspect("equal")
ax.grid(alpha=0.3)
ax.legend(loc="lower center", fontsize=8)
fig.savefig(out / "two_inputs.png", dpi=120)
print(f"written: {out / 'two_inputs.png'}")
