"""Slide inputs: a crank turned by its piston, and a boom lifted by a hydraulic cylinder.

Loads the shipped ``piston_driven_crank`` (a slider-crank whose piston is the input) and
``cylinder_boom`` (a boom lifted by a cylinder between the frame and the boom; the cylinder's
extension is the input). For each it prints the stroke, the output's travel and the balancing force
-- what the piston or the cylinder must push with -- statically and under a cylinder speed; then the
boom's stroke under a constant cylinder force of 9 kN from rest (its time and final speed), and
draws the cylinder's force and the boom's angle over the stroke into ``OUT/slide_inputs.png``
(matplotlib, the ``plot`` extra). Run: ``python examples/slide_inputs.py [OUT]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import linkage
from linkage.kinematics.motion import angle_in_half_turn
from linkage.kinetostatics.reactions import solve_reactions
from linkage.dynamics.stroke import stroke_motion

for name, speed in (("piston_driven_crank", -2.0), ("cylinder_boom", 0.2)):
    mech = linkage.load(name)
    s = np.linspace(*mech.input_range, 41)                       # the stroke, m
    static = solve_reactions(linkage.analyze(mech, s))           # no speed: gravity and the loads only
    moving = solve_reactions(linkage.analyze(mech, s, omega=speed, eps=0.0))
    output, _, _ = linkage.analyze(mech, s, order=0).quantity(mech.output.quantity)
    print(f"{name}: {linkage.structure_of(mech).formula}; stroke {s[0]:.3g} -> {s[-1]:.3g} m; "
          f"{mech.output.quantity} travels {np.ptp(output):.4g}")
    print(f"  balancing force: static {np.min(static.balancing_moment):.1f} .. "
          f"{np.max(static.balancing_moment):.1f} N; at {speed:g} m/s {np.min(moving.balancing_moment):.1f} .. {np.max(moving.balancing_moment):.1f} N")

boom = linkage.load("cylinder_boom")
stroke = stroke_motion(boom, force=9000.0, initial_speed=0.0, positions=40)
print(f"cylinder_boom under 9000 N from rest: the stroke takes {stroke.t[-1]:.4f} s and ends at "
      f"{stroke.speed[-1]:.3f} m/s; the balancing force under this motion stays within "
      f"{np.max(np.abs(stroke.reactions().balancing_moment - 9000.0)):.2g} N of the cylinder's")

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("slide_inputs_out")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: pip install 'linkage[plot]' to draw the curves")
    raise SystemExit(0)
out.mkdir(parents=True, exist_ok=True)
s = np.linspace(*boom.input_range, 141)
motion = linkage.analyze(boom, s)
static = solve_reactions(motion)
fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.0, 6.0), sharex=True, layout="constrained")
top.plot(s, static.balancing_moment / 1000, lw=2, label="static (payload and weights)")
top.plot(stroke.s, stroke.reactions().balancing_moment / 1000, "o", ms=4, label="under 9 kN from rest (= 9 kN)")
top.set(ylabel="cylinder force, kN", title="Boom lifted by a hydraulic cylinder")
top.legend(fontsize=8)
top.grid(alpha=0.3)
boom_angle = np.degrees(np.unwrap(angle_in_half_turn(motion.quantity("1.theta")[0])))
bottom.plot(s, boom_angle, lw=2, color="C2")
bottom.set(xlabel="cylinder extension s = CB, m", ylabel="boom angle, deg")
bottom.grid(alpha=0.3)
fig.savefig(out / "slide_inputs.png", dpi=120)
print(f"written: {out / 'slide_inputs.png'}")
