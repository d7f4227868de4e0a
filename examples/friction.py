"""Friction in the pairs of the course press: the power lost in each pair and the efficiency.

Run: ``python examples/friction.py [OUTPUT_DIR]`` (default ``out/``); needs the ``plot`` extra
(``pip install "linkage[plot]"``). The scheme ``course_slider_crank`` declares its pairs'
friction in ``[friction]`` (docs/friction.md). Prints the efficiency and the power lost at the 13
table positions and the works of one turn; writes ``friction.png`` and ``friction.svg``: (a) the
power lost in each pair and in all, (b) the efficiency η(φ) and the cycle efficiency.
"""

import sys
from pathlib import Path

import numpy as np

import linkage
from linkage.kinetostatics.efficiency import cycle_works
from linkage.kinetostatics.reactions import solve_reactions

try:
    import matplotlib

    matplotlib.use("Agg")
    from linkage.report.friction_plots import plot_friction
except ImportError:
    print('pictures need matplotlib: pip install "linkage[plot]"')
    sys.exit(0)

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)

mech = linkage.load("course_slider_crank")
omega = -10.472                                   # rad/s, the scheme's mean speed (clockwise)
phi = linkage.table_angles(mech, 12, direction=-1)  # 13 positions from the slider's far extreme
motion = linkage.analyze(mech, phi, order=2, omega=omega, eps=0.0)
ends = np.zeros(len(phi), bool)
ends[-1] = True                                   # position 13 closes the cycle (the load's end value)
reactions = solve_reactions(motion, ends=ends, friction=True)

print(" i  efficiency  power lost, W")
for i, (eta, lost) in enumerate(zip(reactions.efficiency(), -reactions.friction_power()), start=1):
    print(f"{i:2d}  {eta:10.4f}  {lost:13.1f}")
works = cycle_works(mech, omega)
print(f"one turn at {omega} rad/s: driving work {works.driving:.1f} J, useful {works.useful:.1f} J, "
      f"friction {works.friction:.1f} J, cycle efficiency {works.efficiency:.4f}")

fig = plot_friction(reactions, cycle=works)
for fmt in ("png", "svg"):
    fig.savefig(out / f"friction.{fmt}", dpi=150)
matplotlib.pyplot.close(fig)
print(f"{out / 'friction'}.png, .svg")
