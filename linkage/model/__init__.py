"""The description of a mechanism: the first stage, reading nothing but the declaration.

Links and pairs as a graph (:mod:`~linkage.model.mechanism`: the frozen :class:`Mechanism`, whose
mappings are read-only), the :class:`MechanismBuilder` that declares one and validates every
problem at once (:mod:`~linkage.model.builder`), the checks of declared numbers every section's
parser shares (:mod:`~linkage.model.numbers`: ranges, angles in rad or deg, unknown keys), the
laws further inputs follow (:mod:`~linkage.model.input_laws`), and scheme files
(:mod:`~linkage.model.scheme`: TOML read, validated and written back; later stages register the
sections and checks they own).
"""

from .builder import MechanismBuilder
from .input_laws import InputLaw
from .mechanism import Link, Mechanism, Prismatic, Revolute
from .scheme import dumps, load, loads, save, section_of, shipped_schemes

__all__ = ["InputLaw", "Link", "Mechanism", "MechanismBuilder", "Prismatic", "Revolute", "dumps", "load", "loads",
           "save", "section_of", "shipped_schemes"]
