"""The course pipeline on the shipped course example, in Python.

Run: ``python examples/course_pipeline.py [OUTPUT_DIR]``. Prints the flywheel sizing by the course
method and by the exact energy method, the crank's law of motion and the balancing moment under
it, and (with matplotlib) draws omega(phi) and M_b(phi) into OUTPUT_DIR (default ``out/``).
"""

import sys
from pathlib import Path


import linkage
from linkage.dynamics.pipeline import run_dynamics

mech = linkage.load("course_slider_crank")
print(linkage.structure_of(mech).formula)

report = run_dynamics(mech, "course")
summary = report.summary()
print(f"driving moment           M_d = {summary['driving_moment']:.2f} N m")
print(f"required constant inertia I' = {summary['required_constant_inertia']:.3f} kg m^2 (course)")
print(f"                             = {summary['exact_required_constant_inertia']:.3f} kg m^2 (exact)")
print(f"flywheel                I_fw = {summary['flywheel_inertia']:.3f} kg m^2")
print(f"coefficient of dynamics      = {summary['dynamic_coefficient']:.3f}")

columns = report.columns()
print("\n  i   phi, deg   omega, rad/s   eps, rad/s^2   M_b, N m")
for i, (phi, w, e, mb) in enumerate(zip(columns["phi_deg"], columns["omega"], columns["eps"],
                                        columns["balancing_moment"]), start=1):
    print(f"{i:3d} {phi:10.2f} {w:14.4f} {e:14.4f} {mb:10.2f}")

try:
    import matplotlib

    matplotlib.use("Agg")
    from linkage.report.plots import draw_mechanism, plot_dynamics
except ImportError:
    sys.exit(0)
out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
out.mkdir(parents=True, exist_ok=True)
# M_b(phi) with the mean driving moment, omega(phi) and eps(phi); positions 1..13 numbered along the
# top, the slider's extreme positions marked
fig = plot_dynamics(report, ["balancing_moment"])
fig.savefig(out / "course_balancing_moment.png", dpi=150)
fig = plot_dynamics(report, ["omega", "eps"])
fig.savefig(out / "course_omega_eps.png", dpi=150)
motion = linkage.analyze(mech, report.law.phi)
ax = draw_mechanism(motion, 10, trajectories=["S2"])      # position 11: the working stroke
ax.figure.savefig(out / "course_mechanism.png", dpi=150)
print(f"\nplots written to {out}/")
