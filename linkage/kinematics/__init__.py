"""Kinematics: where every link is, and its analogs, over the input coordinate.

Reads the mechanism (:mod:`linkage.model`) and its decomposition (:mod:`linkage.structure`).
The inputs' poses (:mod:`~.inputs`), assembly modes, their conditions and change points
(:mod:`~.assembly`), the motion over input angles or slides with a status per position
(:mod:`~.motion`), the extreme positions of an output (:mod:`~.extremes`), batches of design
variants (:mod:`~.batch`), whether a geometry runs as required (:mod:`~.feasibility`), and the
checks loading a scheme runs on its motion (:mod:`~.checks`).
"""

from . import checks  # noqa: F401  (registers the load-time checks of the motion)
from .batch import VariantMotion, analyze_variants, geometry_of
from .extremes import Extremes, extreme_positions, table_angles
from .motion import BranchWarning, Motion, analyze, input_sweep, parse_quantity, position_column, table_positions_deg

__all__ = ["BranchWarning", "Extremes", "Motion", "VariantMotion", "analyze", "analyze_variants", "extreme_positions",
           "geometry_of", "input_sweep", "parse_quantity", "position_column", "table_angles", "table_positions_deg"]
