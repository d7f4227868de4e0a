"""linkage: a graph-based generic planar linkage solver.

A mechanism is a graph of links and kinematic pairs (:mod:`linkage.model`), declared in a
scheme file or in Python; it is decomposed into Assur groups (:mod:`linkage.structure`) whose
solvers (package :mod:`assur`) give positions and exact transfer functions
(:mod:`linkage.kinematics`), reactions (:mod:`linkage.kinetostatics`) and the machine's dynamics
(:mod:`linkage.dynamics`). Course assignments (:mod:`linkage.course`), enumerations
(:mod:`linkage.research`), reports (:mod:`linkage.report`) and the ``linkage`` command
(:mod:`linkage.cli`) are built on them.
"""

from . import dynamics, kinetostatics  # noqa: F401  (register the [loads] and [dynamics] sections)
from .errors import (AssemblyError, ConvergenceError, InputError, LinkageError, PlausibilityWarning, SchemeError,
                     StructureError)
from .kinematics import VariantMotion, analyze, analyze_variants, extreme_positions, geometry_of, table_angles
from .kinematics.motion import Motion
from .model import InputLaw, Mechanism, MechanismBuilder, dumps, load, loads, save, shipped_schemes
from .structure import decompose, mobility, structure_of
from .version import __version__

__all__ = [
    "AssemblyError", "ConvergenceError", "InputError", "LinkageError", "PlausibilityWarning", "SchemeError",
    "StructureError", "InputLaw",
    "Mechanism", "MechanismBuilder", "Motion", "VariantMotion", "analyze", "analyze_variants", "decompose",
    "geometry_of", "dumps", "extreme_positions", "load",
    "loads", "mobility", "save", "shipped_schemes", "structure_of", "table_angles", "__version__",
]
