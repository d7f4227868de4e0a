"""Plausibility notes: values a scheme may hold that are valid but almost never meant.

A crank typed in millimetres (``length = 74``: a 74 m crank), gravity pointing up, radians typed
into ``*_deg`` keys, a mean speed in rpm typed into ``mean_speed`` (rad/s): each is a valid
scheme that analyses to numbers nobody wanted, without an error. When a scheme is loaded
(:func:`linkage.model.scheme.loads`), these checks give a :class:`~linkage.errors.PlausibilityWarning`
naming the file, the key and the value, and saying how to silence it:

- ``lengths``: a link whose points lie more than :data:`MAX_LENGTH` (50 m) apart;
- ``masses``: the declared masses out of scale with the mechanism's size: their sum over
  ``size^3`` (kg/m^3; a slender steel rod gives about 1 to 100, solid steel 7850) outside
  :data:`DENSITY_RANGE` -- lengths in mm with masses in kg give about 1e-9 to 1e-5. Not said
  when ``lengths`` is (one cause, one note);
- ``gravity``: ``[loads] gravity`` with a positive y component (y is up: gravity down is
  ``[0, -9.81]``);
- ``degrees``: two or more nonzero ``*_deg`` values, every one within ±2π and not all whole
  numbers: radians (fractions of π) typed into degree keys;
- ``speed``: a speed of the input or of the motor over :data:`MAX_RPM` (10000 rpm), in rpm or
  rad/s keys (and ``--rpm`` / ``--omega`` on the command line, :func:`warn_fast_speed`).

A scheme silences the checks it means with ``[checks] silence = ["lengths", "gravity"]``
(:func:`parse_checks`, registered as the section ``checks``; an unknown name is an error naming
the key); Python code with ``warnings.filterwarnings("ignore", category=linkage.PlausibilityWarning)``.

Each note is given once per check and keys within one warnings context (the process, or one
``warnings.catch_warnings()`` block: the command line runs each command in one), so the
thousands of variants a course template is drawn into say it once, not once per variant.

>>> import warnings, linkage
>>> text = linkage.dumps(linkage.load("four_bar")).replace("gravity = [0.0, -9.81]", "gravity = [0.0, 9.81]")
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     mech = linkage.loads(text, source="up.toml")
>>> print(caught[0].message)  # doctest: +ELLIPSIS
up.toml: loads.gravity = [0, 9.81] m/s^2 points up: y is up, so gravity down is [0, -9.81]...
"""

from __future__ import annotations

import difflib
import math
import warnings
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from ..errors import PlausibilityWarning
from .mechanism import Mechanism

__all__ = ["CHECKS", "MAX_LENGTH", "DENSITY_RANGE", "MAX_RPM", "parse_checks", "implausible", "warn_implausible",
           "warn_fast_speed"]

#: The checks a scheme may silence (``[checks] silence = [...]``): name -> what it notes.
CHECKS = {
    "lengths": "a link over 50 m long (lengths typed in mm?)",
    "masses": "masses out of scale with the mechanism's size (lengths in mm, or masses in g?)",
    "gravity": "gravity pointing up (y is up)",
    "degrees": "radians typed into *_deg keys",
    "speed": "a speed over 10000 rpm",
}
#: Longest distance between two points of one link that passes without a note, m.
MAX_LENGTH = 50.0
#: Range of (sum of the declared masses) / size^3 that passes without a note, kg/m^3. The
#: shipped schemes span 8.5 (cylinder_boom) to 8.4e4 (slider_crank's 900 kg of rod and piston
#: on a 0.22 m rod), the shipped templates' variants up to 1.6e5 (press_slider_crank); typed in
#: mm they would give 8.5e-9 to 1.6e-4.
DENSITY_RANGE = (1e-3, 1e7)
#: Fastest speed that passes without a note, rpm.
MAX_RPM = 10_000.0
_RPM = math.pi / 30  # rad/s per rpm
#: The speeds of ``[dynamics]`` and ``[dynamics.motor]``: key -> True when it is in rpm (else rad/s).
_SPEED_KEYS = {"mean_rpm": True, "mean_speed": False, "initial_rpm": True, "initial_speed": False}
_MOTOR_SPEED_KEYS = {"synchronous_rpm": True, "rated_rpm": True, "no_load_rpm": True, "no_load_speed": False}


def parse_checks(mech: Mechanism, raw: Any) -> tuple[frozenset[str], list[str]]:
    """The checks a scheme silences (``[checks] silence = ["lengths", ...]``) and the problems.

    Parameters
    ----------
    mech : Mechanism
        Not used (the section parser's signature).
    raw : mapping or None
        The ``[checks]`` table; None when the scheme has none.

    Returns
    -------
    (frozenset of str, list of str)
        The silenced checks' names (see :data:`CHECKS`) and the problems, each naming the key.
    """
    if raw is None:
        return frozenset(), []
    known = ", ".join(f'"{name}"' for name in CHECKS)
    if not isinstance(raw, Mapping):
        return frozenset(), [f"expected a table such as {{silence = [\"lengths\"]}} (checks: {known}), got {raw!r}"]
    problems = [f"unknown key {key!r}" + _hint(key, ["silence"]) + " (the table holds silence = [...], "
                f"the checks to silence: {known})" for key in raw if key != "silence"]
    names = raw.get("silence", [])
    if not (isinstance(names, list) and all(isinstance(name, str) for name in names)):
        return frozenset(), problems + [f"silence: expected a list of check names ({known}), got {names!r}"]
    problems += [f"silence: unknown check {name!r}{_hint(name, CHECKS)} (the checks: {known})"
                 for name in names if name not in CHECKS]
    return frozenset(names), problems


def _hint(name: str, known) -> str:
    meant = difflib.get_close_matches(name, list(known), n=1)
    return f"; did you mean {meant[0]!r}?" if meant else ""


def implausible(data: Mapping[str, Any], mech: Mechanism) -> list[tuple[str, str, str]]:
    """The plausibility notes of a loaded scheme, but those its ``[checks]`` silences.

    Parameters
    ----------
    data : mapping
        The parsed scheme file (valid: :func:`linkage.model.scheme.from_dict` accepted it).
    mech : Mechanism
        The mechanism built from it (its part ``checks``: the silenced checks).

    Returns
    -------
    list of (str, str, str)
        ``(check, keys, message)``: the check's name (:data:`CHECKS`), the keys it names, and the
        note without the file's name; ``masses`` is left out when ``lengths`` is said (one
        cause). A few operations per link and key: cheap.
    """
    silenced = mech.parts.get("checks") or frozenset()
    notes = [] if "lengths" in silenced else _long_links(data, mech)
    if not notes:
        notes += _masses(mech)
    notes += _gravity(data) + _degrees(data) + _speeds(data, mech)
    return [note for note in notes if note[0] not in silenced]


def warn_implausible(data: Mapping[str, Any], mech: Mechanism, source: str) -> None:
    """Warn (:class:`~linkage.errors.PlausibilityWarning`) of every note of :func:`implausible`,
    each prefixed with ``source`` (the file) and given once per check and keys in a warnings
    context."""
    for check, keys, message in implausible(data, mech):
        _say(check, keys, f"{source}: {message}")


def warn_fast_speed(option: str, speed: float, mech: Mechanism | None = None) -> None:
    """Warn of a speed given on the command line (``option``: ``"--rpm 12000"``; ``speed``:
    rad/s) over :data:`MAX_RPM`, unless ``mech`` silences ``speed`` (or is driven by a slide,
    whose speed is in m/s)."""
    if mech is not None and ("speed" in (mech.parts.get("checks") or ()) or not mech.coordinate.is_angle):
        return
    if abs(speed) > MAX_RPM * _RPM:
        _say("speed", option, f"{option}: {_fast(speed)}; silence this note with [checks] silence = "
                              "[\"speed\"] in the scheme")


# ----------------------------------------------------------------------------------------------
# the checks: each a list of (check, keys, message)
# ----------------------------------------------------------------------------------------------


def _silence(check: str) -> str:
    return f" (if meant, silence this note with [checks] silence = [\"{check}\"] in the scheme)"


def _listed(items: list[str], limit: int = 4) -> str:
    return ", ".join(items[:limit]) + (f" and {len(items) - limit} more" if len(items) > limit else "")


def _link_size(link) -> float:
    """The largest distance between two points (or guide points) of a link, m."""
    pts = np.array(list(link.points.values()) + [g.point for g in link.guides.values()], dtype=float).reshape(-1, 2)
    if len(pts) < 2:
        return 0.0
    return float(np.max(np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))))


def _long_links(data: Mapping[str, Any], mech: Mechanism) -> list[tuple[str, str, str]]:
    raw_links = data.get("links", {})
    found = []
    for name in sorted(mech.links):
        size = _link_size(mech.links[name])
        if size > MAX_LENGTH:
            spec = raw_links.get(name, {})
            key = "length" if "length" in spec else "points" if "points" in spec else "guides"
            found.append((f"links.{name}.{key}", size))
    if not found:
        return []
    shown = _listed([f"{key} ({size:.6g} m)" for key, size in found])
    return [("lengths", ", ".join(key for key, _ in found),
             f"{shown}: {'a link is' if len(found) == 1 else 'links are'} over {MAX_LENGTH:g} m long (the largest "
             f"distance between two of its points): lengths are in m; was a length typed in mm?" + _silence("lengths"))]


def _masses(mech: Mechanism) -> list[tuple[str, str, str]]:
    massive = sorted(name for name, link in mech.links.items() if link.mass_declared and link.mass > 0)
    total = sum(mech.links[name].mass for name in massive)
    if not total:
        return []
    density = total / mech.size**3
    low, high = DENSITY_RANGE
    if low <= density <= high:
        return []
    keys = _listed([f"links.{name}.mass" for name in massive])
    cause = "a length typed in mm" if density < low else "a mass typed in g, or a length in km"
    return [("masses", keys, f"{keys}: the masses (total {total:.6g} kg) are out of scale with the mechanism's "
             f"size ({mech.size:.6g} m, the largest distance between two points of one link): mass / size^3 = "
             f"{density:.3g} kg/m^3, outside [{low:g}, {high:g}] (solid steel is 7850 kg/m^3); lengths are in m "
             f"and masses in kg: was {cause}?" + _silence("masses"))]


def _gravity(data: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    loads = data.get("loads")
    gravity = loads.get("gravity") if isinstance(loads, Mapping) else None
    if not (isinstance(gravity, list) and len(gravity) == 2 and gravity[1] > 0):
        return []
    gx, gy = gravity
    return [("gravity", "loads.gravity", f"loads.gravity = [{gx:g}, {gy:g}] m/s^2 points up: y is up, so gravity "
             f"down is [0, -9.81] (the default); was the sign of its y left out?" + _silence("gravity"))]


def _deg_values(value: Any, key: str) -> Iterator[tuple[str, float]]:
    """``(key, number)`` for every number of a ``*_deg`` key in ``value`` (tables, lists, lists
    of tables), keys named as the loader names them (``pairs.P.angle_deg``, ``loads.forces[0].angle_deg``)."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            if k != "checks":
                yield from _deg_values(v, f"{key}.{k}" if key else str(k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _deg_values(v, f"{key}[{i}]" if isinstance(v, Mapping) else key)
    elif key.endswith("_deg") and isinstance(value, (int, float)) and not isinstance(value, bool):
        yield key, float(value)


def _degrees(data: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    found = list(_deg_values(data, ""))
    nonzero = [(key, v) for key, v in found if v != 0]
    if len(nonzero) < 2 or any(abs(v) > 2 * math.pi for _, v in found) or all(v.is_integer() for _, v in nonzero):
        return []
    shown = _listed(list(dict.fromkeys(f"{key} = {v:g}" for key, v in nonzero)))
    sample = max((v for _, v in nonzero), key=abs)
    return [("degrees", ", ".join(dict.fromkeys(key for key, _ in nonzero)),
             f"{shown}: every *_deg value lies within ±2π (±{2 * math.pi:.4g}) and they are not whole numbers: "
             f"radians typed into degree keys? Keys ending in _deg are in degrees ({sample:g} rad would be "
             f"{math.degrees(sample):.6g} deg)" + _silence("degrees"))]


def _fast(speed: float) -> str:
    return (f"{abs(speed) / _RPM:.6g} rpm ({abs(speed):.6g} rad/s) is over {MAX_RPM:g} rpm: rpm keys are in rpm, "
            "speed keys and --omega in rad/s")


def _speeds(data: Mapping[str, Any], mech: Mechanism) -> list[tuple[str, str, str]]:
    dynamics = data.get("dynamics")
    if not isinstance(dynamics, Mapping):
        return []
    motor = dynamics.get("motor")
    entries = [(f"dynamics.{k}", dynamics.get(k), in_rpm) for k, in_rpm in _SPEED_KEYS.items()
               if in_rpm or mech.coordinate.is_angle]  # a slide's mean_speed is in m/s
    if isinstance(motor, Mapping):
        entries += [(f"dynamics.motor.{k}", motor.get(k), in_rpm) for k, in_rpm in _MOTOR_SPEED_KEYS.items()]
    notes = []
    for key, value, in_rpm in entries:
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            speed = value * (_RPM if in_rpm else 1.0)
            if abs(speed) > MAX_RPM * _RPM:
                hint = ("" if in_rpm else f"; a speed in rpm goes in the key's _rpm twin "
                        f"({key.rsplit('.', 1)[1].replace('speed', 'rpm')})")
                notes.append(("speed", key, f"{key} = {value:g}: {_fast(speed)}{hint}" + _silence("speed")))
    return notes


# ----------------------------------------------------------------------------------------------
# once per check and keys in a warnings context
# ----------------------------------------------------------------------------------------------

#: ``(the warnings filters list it belongs to, the (check, keys) said)``: ``warnings.catch_warnings``
#: replaces the filters list, so a new context starts with nothing said.
_said: tuple[Any, set[tuple[str, str]]] = (None, set())


def _say(check: str, keys: str, message: str) -> None:
    global _said
    if _said[0] is not warnings.filters:
        _said = (warnings.filters, set())
    if (check, keys) in _said[1]:
        return
    _said[1].add((check, keys))
    warnings.warn(message, PlausibilityWarning, stacklevel=4)
