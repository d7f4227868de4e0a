"""The graphical method of the course press at one position: plans, force polygons, the lever.

Builds the plans of velocities and accelerations, the force polygons and Zhukovsky's lever of the
shipped ``course_slider_crank`` at its table position 12 (the press stroke, 27 142 N on the
slider), prints the velocity plan's vectors, the dyad's force polygon and the balancing moment
two ways (the lever and the kinetostatics), and draws the plans, the polygons, the lever and a
sheet into ``OUT/`` as PNG and SVG (matplotlib, the ``plot`` extra). The same as
``linkage plans course_slider_crank --position 12``. Run: ``python examples/plans.py [OUT]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import linkage
from linkage.kinetostatics.reactions import solve_reactions
from linkage.kinetostatics.plans import build_plans

POSITION = 12                                         # the table's row number, 1 .. 13
mech = linkage.load("course_slider_crank")            # clockwise at 10.472 rad/s, 12 steps
phi = linkage.table_angles(mech, 12, direction=-1)    # rad, positions 1 .. 13
ends = np.arange(len(phi)) == len(phi) - 1            # position 13 ends the cycle (the press load)
motion = linkage.analyze(mech, phi, omega=-10.472, eps=0.0)
plans = build_plans(motion, solve_reactions(motion, ends=ends))
i = POSITION - 1

print(f"position {POSITION}: phi = {np.degrees(phi[i]):.2f} deg, omega = {motion.omega[i]:g} rad/s")
print("plan of velocities (from the pole p):")
for v in plans.velocity.vectors:
    if v.role != "similarity":
        print(f"  {v.step:12s} {v.start:>5s} -> {v.end:5s} {v.kind:15s} {np.hypot(*v.vector[i]):8.4f} m/s")
for link, w in plans.angular_velocity.items():
    eps = plans.angular_acceleration[link][i]
    print(f"  omega_{link} = {w[i] + 0.0:.4f} rad/s, eps_{link} = {eps + 0.0:.3f} rad/s^2")
group = plans.polygons[1]
print(f"force polygon of {group.step} (sums to {group.closure()[i]:.1e} of its forces):")
for f in (*group.forces, *group.internal):
    print(f"  {f.label:7s} {np.hypot(*f.vector[i]):10.1f} N")
print(f"balancing moment: lever {plans.lever.balancing_moment[i]:.3f} N m, "
      f"kinetostatics {plans.reactions.balancing_moment[i]:.3f} N m")

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out")
try:
    from linkage.report.plan_drawings import write_plan_drawings
    written = write_plan_drawings(plans, i, out, stem=f"{mech.name}_position_{POSITION}")
except ImportError as exc:          # no matplotlib: the numbers above are all there is
    print(f"no drawings: {exc}")
else:
    print(f"{len(written)} drawings in {out}/")
