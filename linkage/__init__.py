"""linkage: a graph-based generic planar linkage solver.

A mechanism is a graph of links and kinematic pairs (:mod:`linkage.model`), declared in a
scheme file (:mod:`linkage.scheme`) or in Python; it is decomposed into Assur groups
(:mod:`linkage.structure`) whose solvers (package :mod:`assur`) give positions and exact
transfer functions (:mod:`linkage.kinematics`).
"""

from .errors import AssemblyError, ConvergenceError, InputError, LinkageError, SchemeError, StructureError
from .extremes import extreme_positions, table_angles
from .kinematics import Motion, analyze, structure_of
from .batch import VariantMotion, analyze_variants, geometry_of
from .input_laws import InputLaw
from .model import Mechanism, MechanismBuilder
from .scheme import dumps, load, loads, save, shipped_schemes
from .structure import decompose, mobility
from . import forces, dynamics  # noqa: F401  (register the [loads] and [dynamics] sections)

__all__ = [
    "AssemblyError", "ConvergenceError", "InputError", "LinkageError", "SchemeError", "StructureError", "InputLaw",
    "Mechanism", "MechanismBuilder", "Motion", "VariantMotion", "analyze", "analyze_variants", "decompose",
    "geometry_of", "dumps", "extreme_positions", "load",
    "loads", "mobility", "save", "shipped_schemes", "structure_of", "table_angles",
]
__version__ = "0.1.0"
