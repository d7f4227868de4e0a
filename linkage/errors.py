"""The exception family of the library.

``LinkageError`` is the root; every error the library raises on purpose is one of:

- :class:`SchemeError` -- a mechanism is declared wrongly (bad file, unknown link, bad value);
- :class:`StructureError` -- the mechanism's structure is wrong (mobility, not decomposable);
- :class:`AssemblyError` -- a group cannot be assembled at some input angles;
- :class:`InputError` -- a function of the library was called with a bad argument (an order, a
  direction, a motion without the analogs a computation needs);
- :class:`DynamicsError` -- the machine stalls, runs away, has no steady state, or its numbers
  leave float64's range; :class:`DynamicsInputError` is a bad argument of a dynamics function.

:class:`SchemeError` and :class:`InputError` are also ``ValueError`` s, so code that catches
``ValueError`` keeps working.
"""

from __future__ import annotations

__all__ = ["LinkageError", "SchemeError", "StructureError", "AssemblyError", "InputError",
           "DynamicsError", "DynamicsInputError"]


class LinkageError(Exception):
    """Root of every error raised on purpose by ``linkage`` and ``assur``."""


class SchemeError(LinkageError, ValueError):
    """A mechanism declaration is invalid.

    Parameters
    ----------
    problems : list of str
        Every problem found, each naming the file, the entry and the value.
    """

    def __init__(self, problems: list[str] | str):
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        super().__init__("\n".join(self.problems))


class StructureError(LinkageError):
    """Mobility does not match the inputs, or the graph cannot be decomposed."""


class AssemblyError(LinkageError):
    """A group cannot be assembled (or is singular) at some input angles.

    Attributes
    ----------
    angles_deg : numpy.ndarray
        The offending input angles in degrees.
    """

    def __init__(self, message: str, angles_deg=()):
        self.angles_deg = angles_deg
        super().__init__(message)


class InputError(LinkageError, ValueError):
    """A function was called with a bad argument (a value out of its range, a motion without the
    analogs or speeds the computation needs, an unknown name)."""


class DynamicsError(LinkageError):
    """The machine stalls, runs away, the steady state cannot be found, or the problem's numbers
    leave float64's range (the message says which quantity and why)."""


class DynamicsInputError(DynamicsError, InputError):
    """An argument of a dynamics function is out of range; the message names it and its value."""
