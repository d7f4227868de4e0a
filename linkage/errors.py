"""The exception family of the library.

``LinkageError`` is the root; every error the library raises on purpose is one of:

- :class:`SchemeError` -- a mechanism is declared wrongly (bad file, unknown link, bad value);
- :class:`StructureError` -- the mechanism's structure is wrong (mobility, not decomposable);
- :class:`AssemblyError` -- a group cannot be assembled at some input angles;
  :class:`ConvergenceError` when Newton's method did not converge there for a group it solves;
- :class:`InputError` -- a function of the library was called with a bad argument (an order, a
  direction, a motion without the analogs a computation needs);
- :class:`DynamicsError` -- the machine stalls, runs away, has no steady state, or its numbers
  leave float64's range; :class:`DynamicsInputError` is a bad argument of a dynamics function.

:class:`SchemeError` and :class:`InputError` are also ``ValueError`` s, so code that catches
``ValueError`` keeps working.

One warning lives here too: :class:`PlausibilityWarning`, a scheme that is valid but almost never
meant (lengths typed in mm, gravity pointing up ...; :mod:`linkage.model.plausibility`).
"""

from __future__ import annotations

__all__ = ["LinkageError", "SchemeError", "StructureError", "AssemblyError", "ConvergenceError", "InputError",
           "DynamicsError", "DynamicsInputError", "PlausibilityWarning"]


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


class ConvergenceError(AssemblyError):
    """Newton's method, started from a group's traced assembly mode, did not converge at some
    input angles (or converged to a point that does not close, or to another mode): status -4,
    ``assur.base.NOT_CONVERGED``. The message names the group, the angles and the closure
    residual at each.

    Attributes
    ----------
    angles_deg : numpy.ndarray
        Every offending input angle in degrees (as :class:`AssemblyError`).
    group : str
        The group (e.g. ``"III(2,3,4,5)"``); the first one when several did not converge.
    not_converged_deg : numpy.ndarray (K,)
        The input angles where Newton's method did not converge for ``group``, deg.
    residual : numpy.ndarray (K,)
        The closure residual of the point it reached at each of them, m: the largest opening of
        one of the group's pairs (:meth:`assur.generic.NewtonGroup.closure`).
    size : float
        The mechanism's size, m (``residual / size`` is the relative residual).
    """

    def __init__(self, message: str, angles_deg=(), group: str = "", not_converged_deg=(), residual=(),
                 size: float = 1.0):
        super().__init__(message, angles_deg)
        self.group = group
        self.not_converged_deg = not_converged_deg
        self.residual = residual
        self.size = size


class InputError(LinkageError, ValueError):
    """A function was called with a bad argument (a value out of its range, a motion without the
    analogs or speeds the computation needs, an unknown name)."""


class DynamicsError(LinkageError):
    """The machine stalls, runs away, the steady state cannot be found, or the problem's numbers
    leave float64's range (the message says which quantity and why)."""


class DynamicsInputError(DynamicsError, InputError):
    """An argument of a dynamics function is out of range; the message names it and its value."""


class PlausibilityWarning(UserWarning):
    """A scheme's value is valid but almost never meant: a length over 50 m (typed in mm?),
    masses out of scale with the lengths, gravity pointing up, radians typed into ``*_deg``
    keys, a speed over 10000 rpm (:mod:`linkage.model.plausibility`). The message names the
    file, the key and how to silence it: ``[checks] silence = ["lengths", ...]`` in the scheme,
    or ``warnings.filterwarnings("ignore", category=linkage.PlausibilityWarning)`` in Python."""
