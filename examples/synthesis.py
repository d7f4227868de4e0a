"""Structural synthesis: every six-link mechanism, its Assur groups, and a geometry that turns fully.

The two 1-DOF six-link chains (Watt's and Stephenson's) give five inversions (a frame link modulo
the chain's symmetry) and nine mechanisms (a crank pinned to the frame, modulo the symmetry that
keeps the frame). Each is decomposed into Assur groups (the Watt mechanisms into two dyads, the
Stephenson ones also into a class-III triad or a class-IV tetrad); for each, dimensions are drawn
reproducibly from a seed until one turns the crank fully with every dyad's transmission angle at
least 20 deg. The example prints the table and the catalogue of groups, writes the atlas (a scheme
and a picture per mechanism, the tables) and checks that every written scheme loads and turns
fully. It takes about 20 s.

Run: ``python examples/synthesis.py [OUTPUT_DIR]`` (default ``out/``).
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import linkage
from linkage.kinematics.full_turn import input_cannot_turn
from linkage.research.chains import chains
from linkage.research.synthesis import catalogue, mechanisms
from linkage.research.synthesis_geometry import search_all, write_atlas

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out") / "six_link_atlas"
six = chains(6)
found = mechanisms(6, chain_list=six)
results = search_all(found, seed=1)
write_atlas(out, six, found, results, seed=1)

for t, r in zip(found, results):
    angle = "-" if r.min_transmission_angle_deg is None else f"{r.min_transmission_angle_deg:5.1f} deg"
    print(f"{t.id:12s} {t.chain_label or '':11s} {t.formula:40s} class {t.mechanism_class:4s} "
          f"geometry {'yes' if r.found else 'no '} ({r.draws} draws), smallest transmission angle {angle}")
for g in catalogue(found):
    print(f"{g.kind} class {g.group_class} ({g.links} links, {g.pairs} pairs): {g.mechanisms} mechanisms")

for r in results:
    if r.found:
        mech = linkage.load(out / f"{r.id}.toml")
        assert input_cannot_turn(mech) is None, r.id
print(f"{out}: {sum(r.found for r in results)} schemes that turn fully, a picture per mechanism")
