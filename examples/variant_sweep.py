"""A research sweep in one call: 2000 crank-rocker four-bars, each at 72 crank angles.

Varies the crank OA and the rocker CB of the shipped four-bar, analyses every variant with
``linkage.analyze_variants`` and prints, for the best variants, the rocker's swing and the
smallest transmission angle. Run: ``python examples/variant_sweep.py``.
"""

from __future__ import annotations

import time

import numpy as np

import linkage

mech = linkage.load("four_bar")                 # O-A-B-C: OA = 0.1, AB = 0.3, CB = 0.25, OC = 0.3
crank, rocker = np.meshgrid(np.linspace(0.06, 0.14, 50), np.linspace(0.18, 0.32, 40), indexing="ij")
crank, rocker = crank.ravel(), rocker.ravel()
zero = np.zeros_like(crank)
geometry = {"1": {"A": np.column_stack([crank, zero])},     # a "line" link's end lies at (length, 0)
            "3": {"B": np.column_stack([rocker, zero])}}
phi = np.radians(np.arange(0.0, 360.0, 5.0))

start = time.perf_counter()
batch = linkage.analyze_variants(mech, phi, geometry, order=1)
seconds = time.perf_counter() - start

ok = np.all(batch.status == 0, axis=1)           # variants that run the whole turn, regular
theta3 = np.unwrap(batch.poses["3"][..., 2], axis=1)
swing = np.degrees(np.ptp(theta3, axis=1))
# transmission angle between the coupler AB and the rocker CB: |sin| of their angle difference
between = batch.poses["2"][..., 2] - batch.poses["3"][..., 2]
mu = np.degrees(np.arcsin(np.min(np.abs(np.sin(between)), axis=1)))

print(f"{batch.count} variants x {len(phi)} angles in {seconds * 1e3:.0f} ms; {ok.sum()} run the whole turn")
best = np.argsort(np.where(ok & (mu >= 40.0), -swing, np.inf))[:5]
print(" OA (m)   CB (m)   swing (deg)   min transmission angle (deg)")
for v in best:
    print(f"{crank[v]:.4f}   {rocker[v]:.4f}   {swing[v]:10.2f}   {mu[v]:10.2f}")
