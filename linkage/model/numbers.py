"""Checks of the numbers a declaration gives, shared by every section's parser.

The ranges a declared number may take (:data:`MAX_MAGNITUDE`, :data:`MIN_MAGNITUDE`,
:data:`MAX_ANGLE_DEG`, :data:`MAX_POSITIONS`; ``schemes/README.md``, "Ranges"), the check of one
number against its range (:func:`check_number`), of an angle given in rad or deg
(:func:`angle_from`), of a point's coordinates (:func:`coordinates_from`), and of a table's keys
(:func:`unknown_keys`). The builder, the scheme loader and the sections later stages register
(loads, dynamics) all report their problems through them, in the same words.
"""

from __future__ import annotations

import difflib
import math
from typing import Any, Mapping

__all__ = [
    "MAX_MAGNITUDE",
    "MIN_MAGNITUDE",
    "MAX_ANGLE_DEG",
    "MAX_POSITIONS",
    "Vec",
    "check_number",
    "unknown_keys",
    "angle_from",
    "is_number",
    "coordinates_from",
]

Vec = tuple[float, float]


#: Largest magnitude of a number in a declaration (a length, coordinate, mass, inertia, force,
#: moment, speed, ratio ...). The pipeline multiplies up to six declared numbers (a kinetic energy
#: ``m l^2 omega^2`` has five factors, a dyad's Jacobian determinant three lengths); with every
#: factor within [1e-50, 1e50] such a product stays within [1e-300, 1e300]: finite, and above the
#: smallest normal float64 (2.2e-308). Documented in ``schemes/README.md`` ("Ranges").
MAX_MAGNITUDE = 1e50
#: Smallest magnitude of a number that must be positive or nonzero because it sets a scale or
#: divides (a link's length, a speed, a gear ratio ...); see :data:`MAX_MAGNITUDE`.
MIN_MAGNITUDE = 1e-50
#: Largest magnitude of an angle, degrees: beyond it a float64 no longer holds the angle to
#: 1e-10 of a degree (its spacing at 1e6 is 1.2e-10).
MAX_ANGLE_DEG = 1e6

#: Largest number of positions per revolution of a table (and of table positions a scheme's
#: ``[dynamics]`` may declare): the arrays grow with it.
MAX_POSITIONS = 100_000

_RANGES = {
    # kind: (test, description)
    "real": (lambda v: abs(v) <= MAX_MAGNITUDE, f"a number with |x| <= {MAX_MAGNITUDE:g}"),
    "nonnegative": (lambda v: 0 <= v <= MAX_MAGNITUDE, f"a number in [0, {MAX_MAGNITUDE:g}]"),
    "positive": (lambda v: MIN_MAGNITUDE <= v <= MAX_MAGNITUDE,
                 f"a number in [{MIN_MAGNITUDE:g}, {MAX_MAGNITUDE:g}]"),
    "nonzero": (lambda v: MIN_MAGNITUDE <= abs(v) <= MAX_MAGNITUDE,
                f"a nonzero number with {MIN_MAGNITUDE:g} <= |x| <= {MAX_MAGNITUDE:g}"),
    "angle_deg": (lambda v: abs(v) <= MAX_ANGLE_DEG, f"a number with |x| <= {MAX_ANGLE_DEG:g}"),
    "angle": (lambda v: abs(v) <= math.radians(MAX_ANGLE_DEG),
              f"a number with |x| <= {math.radians(MAX_ANGLE_DEG):.6g}"),
    "fraction": (lambda v: 0 <= v <= 1, "a number in [0, 1]"),
}


def check_number(value: Any, where: str, what: str, problems: list[str], kind: str = "real",
                 unit: str = "") -> float | None:
    """``float(value)`` when it is a finite number in the range ``kind``; else None, with a problem.

    Parameters
    ----------
    value : Any
        The declared value.
    where, what : str
        The entry (``"link '2'"``, ``"pairs.slide"``) and the key (``"length"``) for the message.
    problems : list of str
        Where the problem is appended.
    kind : {"real", "nonnegative", "positive", "nonzero", "angle_deg", "angle", "fraction"}
        The range (see :data:`MAX_MAGNITUDE` and ``schemes/README.md``).
    unit : str
        Unit shown in the message ("m", "kg").

    Returns
    -------
    float or None

    Examples
    --------
    >>> problems = []
    >>> check_number(1e200, "link '2'", "length", problems, "positive", "m")
    >>> problems
    ["link '2': length must be a number in [1e-50, 1e+50] m, got 1e+200"]
    """
    test, description = _RANGES[kind]
    if is_number(value) and test(value):
        return float(value)
    problems.append(f"{where + ': ' if where else ''}{what} must be {description}{' ' + unit if unit else ''}, got {value!r}")
    return None


def unknown_keys(spec: Mapping[str, Any], known, where: str, problems: list[str]) -> set[str]:
    """Report the keys of ``spec`` that are not in ``known``, suggesting the known key meant.

    Returns the known keys that ``spec`` lacks and that an unknown key looks like a misspelling
    of (``{"links"}`` for ``link``): the entry is then incomplete, and the caller may skip it
    instead of reporting the missing key as a second problem of the same cause.

    Examples
    --------
    >>> problems = []
    >>> unknown_keys({"link": ["1", "2"]}, {"links", "kind", "at"}, "pairs.A", problems)
    {'links'}
    >>> problems
    ["pairs.A: unknown keys ['link'] (known: ['at', 'kind', 'links']); did you mean 'links'?"]
    """
    bad = sorted(k for k in spec if k not in known)
    if not bad:
        return set()
    absent = sorted(k for k in known if k not in spec)
    meant = [m[0] for m in (difflib.get_close_matches(str(k), absent, n=1, cutoff=0.6) for k in bad) if m]
    hint = f"; did you mean {', '.join(repr(m) for m in meant)}?" if meant else ""
    problems.append(f"{where + ': ' if where else ''}unknown keys {bad} (known: {sorted(known)}){hint}")
    return set(meant)


def angle_from(spec: Mapping[str, Any], key: str, where: str, problems: list[str], default=0.0):
    """Read ``key`` (rad) or ``key_deg`` (deg) from ``spec``; return radians."""
    has_rad, has_deg = key in spec, f"{key}_deg" in spec
    if has_rad and has_deg:
        problems.append(f"{where}: give either '{key}' or '{key}_deg', not both")
        return default
    raw = spec.get(key, spec.get(f"{key}_deg", None))
    if raw is None:
        return default
    name = f"{key}_deg" if has_deg else key
    value = check_number(raw, where, f"'{name}'", problems, "angle_deg" if has_deg else "angle",
                         "deg" if has_deg else "rad")
    if value is None:
        return default
    return math.radians(value) if has_deg else value


def is_number(x: Any) -> bool:
    """Whether ``x`` is a finite int or float (not a bool)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _vector(raw: Any) -> Vec | None:
    if isinstance(raw, (list, tuple)) and len(raw) == 2 and all(is_number(v) for v in raw):
        return (float(raw[0]), float(raw[1]))
    return None


def coordinates_from(raw: Any, where: str, expected: str, problems: list[str]) -> Vec | None:
    """``(x, y)`` of a declared ``[x, y]``, or None with a problem: not a pair of finite numbers
    (the message says ``expected``), or a coordinate out of range (:data:`MAX_MAGNITUDE`)."""
    vec = _vector(raw)
    if vec is None:
        problems.append(f"{where}: expected {expected}, got {raw!r}")
    elif not all(abs(c) <= MAX_MAGNITUDE for c in vec):
        problems.append(f"{where}: coordinates must be numbers with |x| <= {MAX_MAGNITUDE:g} m, got {raw!r}")
        vec = None
    return vec

