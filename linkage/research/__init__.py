"""Research: many mechanisms from one, measured side by side.

The enumeration of pair kinds over a scheme's chain: every R/P assignment of its pairs and the
source's reference positions (:mod:`~.assignments`); each assignment's mechanism with the
source's geometry, and whether it decomposes into solvable groups (:mod:`~.geometry`); for a
group solved by Newton's method, the assembly mode of the reference position, followed over a
turn and declared by a readable condition (:mod:`~.placement`); every solvable assignment checked
over a full turn and measured, the table and the schemes written (:mod:`~.enumeration`). The
1-DOF planar chains of N links and their symmetry (:mod:`~.chains`); every mechanism of N links, its
Assur groups and the catalogue of groups (:mod:`~.synthesis`), a geometry that turns fully and the
atlas written (:mod:`~.synthesis_geometry`). Reads
every analysis stage and the report's tables. The public API is exported here.
"""

from .assignments import Assignment, PairKind, Reference, assignments, reference_positions
from .chains import (CHAIN_LINKS, Chain, SynthesisExtraMissing, canonical_form, chains, input_choices, inversions,
                     link_orbits, rigid_subchain)
from .enumeration import (
                          COLUMN_UNITS,
                          CRANK_FACTORS,
                          DEFAULT_OMEGA,
                          Combination,
                          Enumeration,
                          Rejected,
                          enumerate_chain,
                          measure,
)
from .placement import MIN_CONDITIONING, build_combination
from .synthesis import GroupCount, GroupUse, Topology, catalogue, mechanisms, topology

__all__ = [
    "CHAIN_LINKS",
    "GroupCount",
    "GroupUse",
    "Topology",
    "catalogue",
    "mechanisms",
    "topology",
    "Chain",
    "SynthesisExtraMissing",
    "canonical_form",
    "chains",
    "input_choices",
    "inversions",
    "link_orbits",
    "rigid_subchain",
    "COLUMN_UNITS",
    "CRANK_FACTORS",
    "DEFAULT_OMEGA",
    "MIN_CONDITIONING",
    "Assignment",
    "Combination",
    "Enumeration",
    "PairKind",
    "Reference",
    "Rejected",
    "assignments",
    "build_combination",
    "enumerate_chain",
    "measure",
    "reference_positions",
]
