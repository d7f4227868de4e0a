"""Kinetostatics: the loads on a moving mechanism and the reactions they cause.

Reads the motion (:mod:`linkage.kinematics`). Loads: gravity, inertia, declared forces and
moments, force diagrams over a stroke (:mod:`~.loads`, which owns a scheme's ``[loads]``);
reactions in every pair and the balancing load, group by group from the farthest
(:mod:`~.reactions`); the same for batches of design variants (:mod:`~.batch`); the graphical
method: plans of velocities and accelerations, force polygons, Zhukovsky's lever
(:mod:`~.plans`).
"""

from .batch import VariantReactions, variant_reactions
from .loads import Loads, loads_of
from .reactions import Reactions, reactions_under, solve_reactions, virtual_power_residual

__all__ = ["Loads", "Reactions", "VariantReactions", "loads_of", "reactions_under", "solve_reactions",
           "variant_reactions", "virtual_power_residual"]
