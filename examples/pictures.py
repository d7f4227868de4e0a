"""Pictures for people of the shipped schemes, as a teacher would print them (A4 text width).

Run: ``python examples/pictures.py [OUTPUT_DIR]`` (default ``out/``); needs the ``plot`` extra
(``pip install "linkage[plot]"``). Writes, in PNG and SVG:

- ``four_bar_coupler_curve``: the four-bar at position 3 with the path of its coupler point E;
- ``flying_shears_positions``: the flying shears at positions 1, 4, 7, 10 at one scale, with the
  knife's path;
- ``slotted_link_two_dyad``: the shaper (crank, slotted rocker, ram) at position 3;
- ``slider_crank_analogs``: the slider's position and its velocity and acceleration analogs
  against the crank angle, the 13 table positions numbered, the extreme positions marked;
- ``course_balancing_moment``: the course press's balancing moment under its law of motion,
  with the mean driving moment.
"""

import sys
from pathlib import Path

import linkage
from linkage.dynamics.pipeline import run_dynamics

try:
    import matplotlib

    matplotlib.use("Agg")
    from linkage.report.plots import draw_mechanism, draw_positions, plot_dynamics, plot_motion
except ImportError:
    print('pictures need matplotlib: pip install "linkage[plot]"')
    sys.exit(0)

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)


def table(name, n=12):
    mech = linkage.load(name)
    return linkage.analyze(mech, linkage.table_angles(mech, n))


def save(fig, name):
    for fmt in ("png", "svg"):
        fig.savefig(out / f"{name}.{fmt}", dpi=150)
    matplotlib.pyplot.close(fig)
    print(f"{out / name}.png, .svg")


save(draw_mechanism(table("four_bar"), 2, trajectories=["E"]).figure, "four_bar_coupler_curve")
save(draw_positions(table("flying_shears"), [0, 3, 6, 9], trajectories=["E"]), "flying_shears_positions")
save(draw_mechanism(table("slotted_link_two_dyad"), 2).figure, "slotted_link_two_dyad")
save(plot_motion(table("slider_crank"), ["B.x", "B.x'", "B.x''"]), "slider_crank_analogs")
report = run_dynamics(linkage.load("course_slider_crank"), compare=False)
save(plot_dynamics(report, ["balancing_moment"]), "course_balancing_moment")
