"""The description of a mechanism: the first stage, reading nothing but the declaration.

Links and pairs as a graph (:mod:`~linkage.model.mechanism`: the frozen :class:`Mechanism` and
the :class:`MechanismBuilder` that validates every problem at once), the laws further inputs
follow (:mod:`~linkage.model.input_laws`), and scheme files (:mod:`~linkage.model.scheme`: TOML
read, validated and written back; later stages register the sections and checks they own).
"""

from .input_laws import InputLaw
from .mechanism import Link, Mechanism, MechanismBuilder, Prismatic, Revolute
from .scheme import dumps, load, loads, save, section_of, shipped_schemes

__all__ = ["InputLaw", "Link", "Mechanism", "MechanismBuilder", "Prismatic", "Revolute", "dumps", "load", "loads",
           "save", "section_of", "shipped_schemes"]
