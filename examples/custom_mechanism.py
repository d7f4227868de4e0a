"""A mechanism that is not shipped, built in Python: a crank driving an oscillating slotted lever
(crank + RPR) whose tip pushes a slider (+ RRP), with a constant resistance on the slider.

Run: ``python examples/custom_mechanism.py [OUTPUT_DIR]``.
"""

import sys
from pathlib import Path

import numpy as np

import linkage
from linkage.kinetostatics.loads import Loads, PointForce
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual

b = linkage.MechanismBuilder("lever_press")
b.link("0", points={"O": (0.0, 0.15), "Q": (0.0, 0.0)},
       guides={"rail": {"through": (0.0, 0.45), "angle_deg": 0}})
b.link("1", line=("O", "A"), length=0.06, mass=1.0, com="O")                  # crank
b.link("2", points={"A": (0.0, 0.0)}, mass=0.2, com="A")                        # block in the slot
b.link("3", line=("Q", "D"), length=0.4, guides={"slot": {"through": "Q", "angle_deg": 0}},
       points={"S3": {"from": "Q", "distance": 0.2}}, mass=3.0, com="S3", inertia=0.04)
b.link("4", line=("D", "F"), length=0.2, points={"S4": {"from": "D", "distance": 0.1}},
       mass=1.0, com="S4", inertia=0.0033)                                      # connecting rod
b.link("5", points={"F": (0.0, 0.0)}, mass=4.0, com="F")                        # slider on the rail
b.revolute("O", "0", "1").revolute("A", "1", "2").revolute("Q", "3", "0")
b.prismatic("slot_A", "3", "2", guide="slot", at="A")
b.revolute("D", "3", "4").revolute("F", "4", "5")
b.prismatic("rail_F", "0", "5", guide="rail", at="F")
b.inputs("1")
b.assembly("D", towards=np.pi / 2, origin="Q")      # the lever points up
b.assembly("F", towards=0.0, origin="D")            # the slider is to the right of D
b.output("F.x", start="max")
mech = b.build()
print(linkage.structure_of(mech).formula)

ext = linkage.extreme_positions(mech)
print(f"stroke of F: {ext.stroke * 1000:.2f} mm between phi = {np.degrees(ext.phi_min):.3f} "
      f"and {np.degrees(ext.phi_max):.3f} deg")

phi = linkage.table_angles(mech, 12)
motion = linkage.analyze(mech, phi, omega=2 * np.pi, eps=0.0)
loads = Loads(forces=(PointForce("F", "5", (-200.0, 0.0)),))
reactions = solve_reactions(motion, loads)
print("virtual-power residual (max):", f"{virtual_power_residual(reactions).max():.1e}")
print("\n  phi, deg    F.x, m    F.x', m/rad    M_b, N m")
for p, x, v, mb in zip(np.degrees(phi), motion.point("F")[:, 0], motion.point_analogs("F")[0][:, 0],
                       reactions.balancing_moment):
    print(f"{p:10.2f} {x:9.4f} {v:14.5f} {mb:11.3f}")

try:
    import matplotlib

    matplotlib.use("Agg")
    from linkage.report.plots import draw_mechanism, plot_motion
except ImportError:
    sys.exit(0)
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)
ax = draw_mechanism(motion, 3, trajectories=["D"])       # position 4, with the lever tip's arc
ax.figure.savefig(out / "lever_press.png", dpi=150)
fig = plot_motion(motion, ["F.x", "F.x'", "F.x''"])      # the slider's position and analogs
fig.savefig(out / "lever_press_slider.png", dpi=150)
print(f"\npictures written to {out}/lever_press.png and {out}/lever_press_slider.png")
