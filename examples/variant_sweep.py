"""A research sweep in one call: 2000 crank-rocker four-bars, each at 72 crank angles.

Varies the crank OA and the rocker CB of the shipped four-bar, analyses every variant with
``linkage.analyze_variants`` and prints, for the best variants, the rocker's swing, the
smallest transmission angle and the peak balancing moment at 10 rad/s (the reactions of all
variants in one more call, ``linkage.kinetostatics.batch.variant_reactions``, with the rocker's mass
scaled with its length), and draws the swing over the two dimensions into
``OUT/variant_sweep.png`` (matplotlib, the ``plot`` extra). Run: ``python examples/variant_sweep.py [OUT]``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import linkage
from linkage.kinetostatics.batch import variant_reactions

mech = linkage.load("four_bar")                 # O-A-B-C: OA = 0.1, AB = 0.3, CB = 0.25, OC = 0.3
crank, rocker = np.meshgrid(np.linspace(0.06, 0.14, 50), np.linspace(0.18, 0.32, 40), indexing="ij")
crank, rocker = crank.ravel(), rocker.ravel()
zero = np.zeros_like(crank)
geometry = {"1": {"A": np.column_stack([crank, zero])},     # a "line" link's end lies at (length, 0)
            "3": {"B": np.column_stack([rocker, zero])}}
phi = np.radians(np.arange(0.0, 360.0, 5.0))

start = time.perf_counter()
batch = linkage.analyze_variants(mech, phi, geometry, order=2)
seconds = time.perf_counter() - start
start = time.perf_counter()
# the rocker CB (2 kg at 0.25 m in the base: a uniform bar of 8 kg/m) keeps its mass per metre,
# its centre of mass in its middle and its J_S = m CB^2 / 12
reactions = variant_reactions(batch, omega=10.0, mass={"3": 8.0 * rocker}, inertia={"3": 8.0 * rocker**3 / 12},
                              center_of_mass={"3": np.column_stack([rocker / 2, zero])})
force_seconds = time.perf_counter() - start
peak_moment = np.max(np.abs(reactions.balancing_moment), axis=1)

ok = np.all(batch.status == 0, axis=1)           # variants that run the whole turn, regular
theta3 = np.unwrap(batch.poses["3"][..., 2], axis=1)
swing = np.degrees(np.ptp(theta3, axis=1))
# transmission angle between the coupler AB and the rocker CB: |sin| of their angle difference
between = batch.poses["2"][..., 2] - batch.poses["3"][..., 2]
mu = np.degrees(np.arcsin(np.min(np.abs(np.sin(between)), axis=1)))

print(f"{batch.count} variants x {len(phi)} angles: kinematics in {seconds * 1e3:.0f} ms, reactions in "
      f"{force_seconds * 1e3:.0f} ms; {ok.sum()} run the whole turn")
best = np.argsort(np.where(ok & (mu >= 40.0), -swing, np.inf))[:5]
print(" OA (m)   CB (m)   swing (deg)   min transmission angle (deg)   peak |M_b| at 10 rad/s (N m)")
for v in best:
    print(f"{crank[v]:.4f}   {rocker[v]:.4f}   {swing[v]:10.2f}   {mu[v]:10.2f}   {peak_moment[v]:26.2f}")

import matplotlib.pyplot as plt  # noqa: E402  (the picture only)

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)
fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
shape = (50, 40)
filled = ax.contourf(crank.reshape(shape) * 1e3, rocker.reshape(shape) * 1e3, swing.reshape(shape), levels=12)
lines = ax.contour(crank.reshape(shape) * 1e3, rocker.reshape(shape) * 1e3, mu.reshape(shape), levels=[40.0],
                   colors="white", linestyles="--")
ax.clabel(lines, fmt="μ_min = 40°")
ax.plot(crank[best[0]] * 1e3, rocker[best[0]] * 1e3, "w*", markersize=12, markeredgecolor="k",
        clip_on=False, zorder=5, label="largest swing with μ_min ≥ 40°")
fig.colorbar(filled, ax=ax, label="swing of the rocker, deg")
ax.set_xlabel("crank OA, mm")
ax.set_ylabel("rocker CB, mm")
ax.set_title(f"{batch.count} four-bars (AB = 300 mm, OC = 300 mm), one call")
ax.legend(loc="upper left")
fig.savefig(out / "variant_sweep.png", dpi=120)
print(f"picture: {out / 'variant_sweep.png'}")
