"""Answer keys for grading a course assignment step by step (``key.json``, ``key.csv``).

:func:`answer_key` computes every number a student hands in for a variant, at the positions of
the variant's tables (the rows of ``kinematics.csv``, ``forces.csv`` and ``dynamics.csv``), each
with the unit, the relative tolerance it is graded with, the significant digits a student
reports and its floor (the quantity's natural scale):

- **kinematics** of the points asked (``[template.grading] points``; default the output point and
  the centres of mass of the moving links that are named points): ``P.x P.y`` (m), the analogs
  ``P.x' P.y'`` (m/rad) and ``P.x'' P.y''`` (m/rad^2) with respect to psi, the angle turned from
  position 1 in the direction of rotation (:func:`linkage.report.tables.per_turned_angle`), and at
  the scheme's ``[dynamics]`` mean speed with the crank's eps = 0 the velocities ``P.vx P.vy P.v``
  (m/s) and accelerations ``P.ax P.ay P.a`` (m/s^2); of every moving link L that turns, besides
  the input links whose motion is given: ``L.theta_deg`` (deg, in (-180, 180]), ``L.theta'``,
  ``L.theta''``, ``L.omega`` (rad/s), ``L.eps`` (rad/s^2);
- **kinetostatics** at the force positions (``[template.grading] force_positions``; default every
  position), at the mean speed as ``linkage forces`` computes it: every pair's reaction ``K.R``
  (N) and its direction ``K.angle_deg`` (deg; the force R[a, b] of link b on link a for the pair
  declared with ``links = [a, b]``), the balancing moment ``balancing_moment`` (N m) and the same
  by Zhukovsky's lever, ``lever_balancing_moment``;
- **dynamics** by the course method (Mertsalov's) per position: ``reduced_moment_resistance`` M_c
  and ``reduced_moment_driving`` M_d (N m), ``reduced_inertia`` I = I_0 + I'',
  ``reduced_inertia_variable`` I'' and ``reduced_inertia_derivative`` dI/dpsi, the work of the
  resistance ``work_resistance`` A_c (trapezoid over the table positions), of the driving moment
  ``work_driving`` A_d = M_d psi, ``delta_T`` = A_d + A_c, ``T_variable`` T'' = I'' w_m^2 / 2,
  ``delta_T_prime`` = Delta T - T'' (J), the crank's ``omega`` (rad/s) and ``eps`` (rad/s^2); the
  scalars ``driving_moment``, ``delta_T_prime_max``, ``delta_T_prime_min``,
  ``delta_T_prime_swing`` (Delta T'_ab), ``reduced_inertia_constant`` (I_0),
  ``required_constant_inertia`` (I' = Delta T'_ab / (delta w_m^2)), ``flywheel_inertia``
  (I_fw = I' - I_0, negative when no flywheel is needed) and ``stroke`` (of the output).

The kinematic items also carry ``other_mode``, the value with every group in its other assembly
mode at the same input angle (for the grader's hint), when the groups have two modes to choose
from. What does not apply is left out, and the key's ``notes`` say so: without a ``[dynamics]`` mean
speed there are no velocities and the reactions are static; without ``delta`` (or over an input
range) no dynamics; without masses or loads no reactions. A value passes when
``|given - expected| <= tolerance * max(|expected|, floor)`` (docs/templates.md, "[template.grading]").

>>> import linkage
>>> key = answer_key(linkage.load("course_slider_crank"))
>>> key.to_csv().splitlines()[0]
'quantity,position,value,unit,tolerance'
>>> round(key.value("driving_moment"), 6), round(key.value("B.x", 1), 6), key.item("B.v", 4).unit
(183.546726, 0.2964, 'm/s')
"""

from __future__ import annotations

import csv
import io
import json
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from assur.base import OK

from ..dynamics.spec import DynamicsSpec
from ..errors import InputError, LinkageError
from ..kinematics.extremes import extreme_positions
from ..kinematics.motion import (
    Motion,
    analyze,
    angle_in_half_turn,
    parse_quantity,
    table_positions_deg,
)
from ..kinetostatics.loads import loads_of
from ..kinetostatics.plans import build_plans
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import Assembly, Mechanism
from ..model.scheme import section_of
from ..report.results import (
    JSON_CONVENTIONS,
    DynamicsResults,
    analog_direction,
    declared_rotation,
    dynamics_results,
    table_defaults,
    table_positions,
    table_sense,
)
from ..report.tables import TABLE_ZERO, column_unit, per_turned_angle
from ..structure import structure_of
from .template import Grading, Template

__all__ = ["KEY_COLUMNS", "KeyItem", "AnswerKey", "answer_key", "default_points", "PASS_RULE"]

#: the columns of ``key.csv``, in order
KEY_COLUMNS = ("quantity", "position", "value", "unit", "tolerance")

#: how a value is graded (written into every key)
PASS_RULE = "a value passes when |given - expected| <= tolerance * max(|expected|, floor)"

#: how the key's analogs are taken (written into every key)
ANALOGS = ("P.x', L.theta' ...: d/dpsi, per rad of crank rotation (psi: the angle turned from position 1 in the "
           "direction of rotation); P.x'', L.theta'': d2/dpsi2")

#: a link whose angle's analog stays below this (rad/rad) over the positions does not turn
_TURNS = 1e-9


@dataclass(frozen=True)
class KeyItem:
    """One number of an answer key: ``quantity`` at table ``position`` (1 .. n+1; None for a
    scalar), its ``value`` at full precision, ``unit``, relative ``tolerance``, the significant
    ``digits`` a student reports and the ``floor`` of the pass rule (:data:`PASS_RULE`); for the
    kinematics, ``other_mode``: the value with every group in its other assembly mode at the same
    input angle (what a student who assembled the mechanism the other way finds; None where the
    key has none)."""

    quantity: str
    position: int | None
    value: float
    unit: str
    tolerance: float
    digits: int
    floor: float
    other_mode: float | None = None

    def as_dict(self) -> dict[str, Any]:
        """The item's entry in ``key.json`` (``other_mode`` only when there is one)."""
        entry = {"quantity": self.quantity, "position": self.position, "value": self.value, "unit": self.unit,
                 "tolerance": self.tolerance, "digits": self.digits, "floor": self.floor}
        if self.other_mode is not None:
            entry["other_mode"] = self.other_mode
        return entry


@dataclass(frozen=True)
class AnswerKey:
    """A variant's answer key: the ``items`` in order (quantity by quantity, each over its
    positions) and ``meta``, the rest of ``key.json`` (``variant``, ``template``, ``parameters``,
    ``checks``, the fields of ``linkage dynamics --format json`` when the dynamics applies,
    ``conventions``, ``digits``, ``tolerance``, ``mean_speed``, ``psi_deg``, ``input_angle_deg``,
    ``pass_rule``, ``analogs``, ``notes``)."""

    items: tuple[KeyItem, ...]
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def notes(self) -> list[str]:
        """What the key leaves out or assumes, one line each."""
        return list(self.meta.get("notes", []))

    @property
    def quantities(self) -> list[str]:
        """The quantity names, in the key's order."""
        return list(dict.fromkeys(item.quantity for item in self.items))

    def item(self, quantity: str, position: int | None = None) -> KeyItem:
        """The item of ``quantity`` at ``position`` (None for a scalar); KeyError when the key has none."""
        for it in self.items:
            if it.quantity == quantity and it.position == position:
                return it
        raise KeyError(f"the key has no {quantity!r}" + (f" at position {position}" if position is not None else ""))

    def value(self, quantity: str, position: int | None = None) -> float:
        return self.item(quantity, position).value

    def series(self, quantity: str) -> dict[int, float]:
        """``{position: value}`` of a per-position quantity."""
        return {it.position: it.value for it in self.items if it.quantity == quantity and it.position is not None}

    def to_json(self) -> str:
        """``key.json``: ``meta`` and ``items`` (one object per item), indented, ending with a newline."""
        doc = {**_plain(self.meta), "items": [it.as_dict() for it in self.items]}
        return json.dumps(doc, ensure_ascii=False, indent=1, allow_nan=False) + "\n"

    def to_csv(self) -> str:
        """``key.csv``: the columns :data:`KEY_COLUMNS`, one row per item, values at full precision
        (``repr``), the position empty for a scalar."""
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(KEY_COLUMNS)
        for it in self.items:
            writer.writerow([it.quantity, "" if it.position is None else it.position, repr(it.value), it.unit,
                             repr(it.tolerance)])
        return out.getvalue()


def _plain(x: Any) -> Any:
    """JSON-ready: numpy numbers and arrays as Python values, non-finite floats as None."""
    if isinstance(x, np.ndarray):
        return [_plain(v) for v in x.tolist()]
    if isinstance(x, np.generic):
        return _plain(x.item())
    if isinstance(x, Mapping):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


# ----------------------------------------------------------------------------------------------
# the quantities, before floors and tolerances
# ----------------------------------------------------------------------------------------------


@dataclass
class _Quantity:
    """One quantity's values ``{position: value}`` (a scalar: ``{None: value}``), its unit and the
    family whose largest magnitude is its floor."""

    name: str
    unit: str
    values: dict
    family: str
    scale: np.ndarray | None = None   # magnitudes that set the family's floor besides the values
    optional: bool = False            # left out when it is 0 at every position (a component that never moves)
    other: dict | None = None         # {position: value} in the other assembly mode


def default_points(mech: Mechanism) -> tuple[str, ...]:
    """The points a key asks by default: the output point and the centres of mass of the moving
    links with a mass that sit at a named point of their link; points of the frame (which do not
    move) left out.

    >>> import linkage
    >>> default_points(linkage.load("course_slider_crank"))
    ('B', 'S2')
    """
    found = []
    if mech.output_point is not None:
        found.append(mech.output_point)
    for k in mech.moving_links:
        link = mech.links[k]
        if not link.mass > 0:
            continue
        at = [p for p, local in sorted(link.points.items()) if np.allclose(local, link.center_of_mass, rtol=0,
                                                                           atol=1e-12)]
        found += at[:1]
    return tuple(p for p in dict.fromkeys(found) if mech.point_link(p) != mech.frame)


def _kinematics(mech: Mechanism, motion: Motion, rows: list[int], points, speed: float | None,
                notes: list[str]) -> list[_Quantity]:
    """Positions, analogs d/dpsi, velocities and accelerations of the points; angles, analogs,
    angular velocities and accelerations of the links that turn."""
    angle = mech.coordinate.is_angle
    direction = analog_direction(mech, motion.phi)
    per = "rad" if angle else "m"
    at = np.asarray(rows) - 1
    found: list[_Quantity] = []

    def add(name, unit, values, family, scale=None, optional=False):
        found.append(_Quantity(name, unit, dict(zip(rows, np.asarray(values, float)[at].tolist())), family,
                               None if scale is None else np.asarray(scale, float)[at], optional))

    for p in points:
        xy = motion.point(p)
        d1, d2 = motion.point_analogs(p)
        columns = per_turned_angle({f"{p}.x": xy[:, 0], f"{p}.y": xy[:, 1], f"{p}.x'": d1[:, 0], f"{p}.y'": d1[:, 1],
                                    f"{p}.x''": d2[:, 0], f"{p}.y''": d2[:, 1]}, direction)
        for prime, vector in (("", xy), ("'", d1), ("''", d2)):
            for axis in "xy":
                name = f"{p}.{axis}{prime}"
                add(name, column_unit(name, per), columns[name], f"{p}.r{prime}", np.hypot(*vector.T), bool(prime))
        if speed is not None:
            for kind, vector, unit in (("v", motion.velocity(p), "m/s"), ("a", motion.acceleration(p), "m/s^2")):
                size = np.hypot(*vector.T)
                add(f"{p}.{kind}x", unit, vector[:, 0], f"{p}.{kind}", size, True)
                add(f"{p}.{kind}y", unit, vector[:, 1], f"{p}.{kind}", size, True)
                add(f"{p}.{kind}", unit, size, f"{p}.{kind}")
    if not angle:
        return found
    inputs = set(motion.structure.inputs)
    still = []
    for k in mech.moving_links:
        if k in inputs or k not in motion.poses:
            continue
        theta, t1, t2 = motion.poses[k][:, 2], motion.first[k][:, 2], motion.second[k][:, 2]
        if not np.nanmax(np.abs(t1[at])) > _TURNS:
            still.append(k)
            continue
        columns = per_turned_angle({f"{k}.theta'": t1, f"{k}.theta''": t2}, direction)
        add(f"{k}.theta_deg", "deg", np.degrees(angle_in_half_turn(theta)), f"{k}.theta_deg")
        add(f"{k}.theta'", column_unit(f"{k}.theta'"), columns[f"{k}.theta'"], f"{k}.theta'")
        add(f"{k}.theta''", column_unit(f"{k}.theta''"), columns[f"{k}.theta''"], f"{k}.theta''")
        if speed is not None:
            add(f"{k}.omega", "rad/s", t1 * speed, f"{k}.omega")
            add(f"{k}.eps", "rad/s^2", t2 * speed**2, f"{k}.eps")
    if still:
        notes.append(f"{_links(still)} {'does' if len(still) == 1 else 'do'} not turn: angles, angular velocities "
                     "and accelerations left out")
    inputs = motion.structure.inputs
    notes.append(f"the input {_links(inputs)} {'turns' if len(inputs) == 1 else 'turn'} as given: "
                 "not in the key")
    return found


def _links(names) -> str:
    return ("link " if len(names) == 1 else "links ") + ", ".join(names)


def _loaded(mech: Mechanism) -> bool:
    """Whether anything loads the mechanism: a mass, a moment of inertia, a force or a moment."""
    loads = loads_of(mech)
    return bool(loads.forces or loads.moments
                or any(lk.mass > 0 or lk.inertia > 0 for k, lk in mech.links.items() if k != mech.frame))


def _forces(mech: Mechanism, motion: Motion, positions: list[int], speed: float | None,
            notes: list[str]) -> list[_Quantity]:
    """Reactions, balancing moment by the kinetostatics and by Zhukovsky's lever at ``positions``."""
    ends = np.zeros(len(motion.phi), bool)
    ends[-1] = True
    reactions = solve_reactions(motion, inertia=speed is not None, ends=ends)
    lever = build_plans(motion, reactions).lever.balancing_moment
    at = np.asarray(positions) - 1
    found = []
    balancing = np.concatenate([reactions.balancing_moment[at], lever[at]])
    for name, values in (("balancing_moment", reactions.balancing_moment), ("lever_balancing_moment", lever)):
        found.append(_Quantity(name, "N m", dict(zip(positions, values[at].tolist())), "balancing_moment",
                               np.abs(balancing)))
    for pair in sorted(reactions.multipliers):
        found.append(_Quantity(f"{pair}.R", "N", dict(zip(positions, reactions.magnitude(pair)[at].tolist())),
                               f"{pair}.R"))
        found.append(_Quantity(f"{pair}.angle_deg", "deg",
                               dict(zip(positions, reactions.direction_deg(pair)[at].tolist())), f"{pair}.angle_deg"))
    where = (f"positions 1 .. {positions[-1]}" if positions == list(range(1, len(positions) + 1))
             else "positions " + ", ".join(map(str, positions)))
    if speed is None:
        notes.append(f"reactions and balancing moments at {where}, static (gravity and the declared loads, no "
                     "inertia: no mean speed)")
    else:
        notes.append(f"reactions and balancing moments at {where}, at the mean speed omega = {speed:.10g} rad/s with "
                     "eps = 0, as `linkage forces` computes them")
    return found


def _dynamics(results: DynamicsResults, phi: np.ndarray, rows: list[int]) -> list[_Quantity]:
    """The course method's chain per position and its scalars, from its law of motion."""
    law = results.report.law
    if law.method != "course":
        raise InputError(f"an answer key follows the course method (Mertsalov's), got the {law.method!r} method's "
                         "results")
    if len(law.phi) != len(phi) or not np.allclose(law.phi, phi, rtol=0, atol=1e-9):
        raise InputError("the dynamics results are not at the positions of the tables: compute them with the "
                         "scheme's [dynamics] positions and start")
    red = law.reduced
    step = 2 * np.pi / (len(law.phi) - 1)
    resistance = red.moment_resistance
    driving = red.moment_driving + law.driving
    # the course method's own chain (linkage.dynamics.cycle.course_method), the work of all loads
    # split into the resistance's (the same trapezoid over the table positions) and the driving work
    work_resistance = np.concatenate([[0.0], np.cumsum((resistance[1:] + resistance[:-1]) / 2 * step)])
    delta_t = law.details["energy_change"]
    work_driving = delta_t - work_resistance
    t_variable = law.details["energy_links"]
    delta_t_prime = law.details["energy_flywheel"]
    high, low = float(np.max(delta_t_prime)), float(np.min(delta_t_prime))
    required = law.required_constant_inertia
    energy = np.abs(np.concatenate([work_resistance, work_driving, delta_t, t_variable, delta_t_prime]))
    moments = np.abs(np.concatenate([resistance, driving]))
    inertia = np.abs([red.inertia_constant, required, required - red.inertia_constant])

    def per_position(name, unit, values, family, scale=None):
        return _Quantity(name, unit, dict(zip(rows, np.asarray(values, float).tolist())), family, scale)

    def scalar(name, unit, value, family, scale=None):
        return _Quantity(name, unit, {None: float(value)}, family, scale)

    return [
        per_position("reduced_moment_resistance", "N m", resistance, "moments", moments),
        per_position("reduced_moment_driving", "N m", driving, "moments", moments),
        per_position("reduced_inertia", "kg m^2", red.inertia, "reduced_inertia"),
        per_position("reduced_inertia_variable", "kg m^2", red.inertia_variable, "reduced_inertia_variable"),
        per_position("reduced_inertia_derivative", "kg m^2/rad", red.inertia_derivative, "reduced_inertia_derivative"),
        per_position("work_resistance", "J", work_resistance, "energy", energy),
        per_position("work_driving", "J", work_driving, "energy", energy),
        per_position("delta_T", "J", delta_t, "energy", energy),
        per_position("T_variable", "J", t_variable, "energy", energy),
        per_position("delta_T_prime", "J", delta_t_prime, "energy", energy),
        per_position("omega", "rad/s", law.omega, "omega"),
        per_position("eps", "rad/s^2", law.eps, "eps"),
        scalar("driving_moment", "N m", law.driving_moment, "moments", moments),
        scalar("delta_T_prime_max", "J", high, "energy", energy),
        scalar("delta_T_prime_min", "J", low, "energy", energy),
        scalar("delta_T_prime_swing", "J", high - low, "energy", energy),
        scalar("reduced_inertia_constant", "kg m^2", red.inertia_constant, "inertia", inertia),
        scalar("required_constant_inertia", "kg m^2", required, "inertia", inertia),
        scalar("flywheel_inertia", "kg m^2", required - red.inertia_constant, "inertia", inertia),
    ]


def _stroke(mech: Mechanism, notes: list[str]) -> list[_Quantity]:
    """The output's stroke (m; deg for a link angle)."""
    if mech.output is None:
        return []
    try:
        stroke = extreme_positions(mech).stroke
    except LinkageError as exc:
        notes.append(f"no stroke: {exc}")
        return []
    kind, _, _ = parse_quantity(mech, mech.output.quantity)
    if kind == "link":
        return [_Quantity("stroke", "deg", {None: math.degrees(stroke)}, "stroke")]
    return [_Quantity("stroke", "m", {None: float(stroke)}, "stroke")]


# ----------------------------------------------------------------------------------------------
# the key
# ----------------------------------------------------------------------------------------------


def answer_key(mech: Mechanism, grading: Grading | None = None, *, variant: str | None = None,
               template: Template | str | None = None, parameters: Mapping[str, Any] | None = None,
               checks: Mapping[str, Any] | None = None, dynamics: DynamicsResults | None = None) -> AnswerKey:
    """The answer key of a mechanism (a course variant) for grading step by step.

    From :func:`linkage.course.variants.build_variant`::

        key = answer_key(mech, template.grading, variant=variant.label, template=template,
                         parameters=values, checks=variant.figures, dynamics=dynamics)
        files["key.json"], files["key.csv"] = key.to_json().encode(), key.to_csv().encode()

    Parameters
    ----------
    mech : Mechanism
        The variant's mechanism (a plain scheme: ``linkage.load`` or ``Template.mechanism``).
    grading : Grading, optional
        ``[template.grading]``: tolerances, digits, the points asked and the force positions.
        Default: ``template.grading`` when ``template`` is a :class:`Template`, else the defaults
        (2 %, 4 digits, the output point and the named centres of mass, every position).
    variant, template, parameters, checks
        Written into ``key.json`` as they are: the variant's label, the template (its name is
        written), every parameter's value, what the feasibility check measured.
    dynamics : DynamicsResults, optional
        :func:`linkage.report.results.dynamics_results` of ``mech`` (course method, the scheme's
        positions), when the caller has it already (the ``dynamics.csv`` of the same variant);
        computed here otherwise. Its JSON fields go into ``key.json`` unchanged.

    Returns
    -------
    AnswerKey
        ``to_json()`` is ``key.json``, ``to_csv()`` is ``key.csv``.

    Raises
    ------
    InputError
        A point asked that the mechanism does not have, a force position outside the table, or
        ``dynamics`` of another method or other positions.
    LinkageError
        The analyses' own errors (a mechanism that cannot be solved at its table positions ...).
    """
    if grading is None:
        grading = template.grading if isinstance(template, Template) else Grading()
    template_name = template.name if isinstance(template, Template) else template
    notes: list[str] = []
    direction = declared_rotation(mech)
    n, start = table_defaults(mech)
    phi, start = table_positions(mech, n, start, direction, notes)
    rows = list(range(1, len(phi) + 1))
    angle = mech.coordinate.is_angle
    turn = angle and mech.input_range is None
    spec: DynamicsSpec | None = section_of(mech, "dynamics")
    speed = float(spec.mean_speed) if spec is not None and angle else None
    points = _points(mech, grading)
    force_rows = _force_rows(grading, rows)
    omega = speed if speed is not None else (float(direction) if angle else None)
    motion = analyze(mech, phi, order=2, omega=omega, eps=0.0, on_failure="mask")

    kinematic_rows = rows[:-1] if turn else rows   # over a turn, the last row is the first again
    quantities = _kinematics(mech, motion, kinematic_rows, points, speed, notes)
    other = _other_mode(mech, phi, omega)
    if other is not None:
        flipped = {q.name: q.values for q in _kinematics(mech, other, kinematic_rows, points, speed, [])}
        for q in quantities:
            q.other = flipped.get(q.name)
    if turn:
        notes.append(f"kinematics at positions 1 .. {n}: position {n + 1} is position 1 again")
    meta_dynamics: dict[str, Any] = {}
    if not angle:
        notes.append("a slide input: the positions of the points and their analogs per m of the slide only (no "
                     "velocities, reactions or dynamics)")
    else:
        if speed is None:
            notes.append("no [dynamics] mean speed: no velocities, accelerations or angular velocities")
        if _loaded(mech):
            quantities += _forces(mech, motion, force_rows, speed, notes)
        else:
            notes.append("no masses and no loads: no reactions or balancing moments")
        if not turn or spec is None or spec.delta is None:
            why = ("no full turn (an input range)" if not turn else "no [dynamics] section" if spec is None
                   else "no delta in [dynamics]")
            notes.append(f"{why}: no dynamics (reduced moments, work, Mertsalov's flywheel, omega and eps of the "
                         "crank)")
        else:
            results = dynamics if dynamics is not None else dynamics_results(mech)
            quantities += _dynamics(results, phi, rows)
            meta_dynamics = json.loads(results.json())
    quantities += _stroke(mech, notes)
    items, skipped = _items(quantities, grading, notes)
    if skipped:
        notes.append(f"positions where the mechanism cannot be assembled or is singular are left out: "
                     f"{', '.join(str(i) for i in skipped)}")

    meta: dict[str, Any] = {"variant": variant, "template": template_name, "parameters": dict(parameters or {}),
                            "checks": dict(checks or {})}
    base = {"scheme": mech.name, "positions": n, "direction": table_sense(phi)}
    meta.update(meta_dynamics or base)
    extra = {"conventions": JSON_CONVENTIONS, "digits": grading.digits, "tolerance": grading.tolerance,
             "mean_speed": speed, "delta": None if spec is None else spec.delta,
             "psi_deg": table_positions_deg(phi, table_sense(phi)).tolist() if angle else None,
             "input_angle_deg": np.degrees(phi).tolist() if angle else None,
             "pass_rule": PASS_RULE, "analogs": ANALOGS if angle else "d/ds: per m of the input's slide s",
             "points": list(points), "force_positions": force_rows, "notes": notes}
    if not angle:
        extra["input_slide"] = np.asarray(phi, float).tolist()
    for k, v in extra.items():
        if k not in meta:
            meta[k] = v
    return AnswerKey(tuple(items), meta)


def _flipped(rule: Assembly) -> Assembly:
    """The assembly condition that picks the other branch of a two-branch group."""
    if rule.rule in ("left_of", "right_of"):
        return replace(rule, rule="right_of" if rule.rule == "left_of" else "left_of")
    if rule.rule == "towards":
        return replace(rule, angle=rule.angle + math.pi)
    return replace(rule, value=-rule.value)


def _other_mode(mech: Mechanism, phi: np.ndarray, omega: float | None) -> Motion | None:
    """The motion with every group in its other assembly mode, at the same input angles; None when
    a group has no two branches to choose from (a single branch, or several modes traced by
    Newton's method), there is no assembly condition to flip, or the other mode does not assemble
    at every angle."""
    groups = structure_of(mech).groups
    if not mech.assembly or any(getattr(g, "tracked", False) or set(g.branches) - {1, -1} for g in groups):
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            other = analyze(replace(mech, assembly=tuple(_flipped(r) for r in mech.assembly)), phi, order=2,
                            omega=omega, eps=0.0, on_failure="mask")
    except LinkageError:
        return None
    return other if np.all(other.status == OK) else None


def _points(mech: Mechanism, grading: Grading) -> tuple[str, ...]:
    if grading.points is None:
        return default_points(mech)
    unknown = [p for p in grading.points if p not in mech.point_names]
    if unknown:
        raise InputError(f"[template.grading] points: {unknown} are not points of mechanism '{mech.name}' (its "
                         f"points: {', '.join(mech.point_names)})")
    return tuple(grading.points)


def _force_rows(grading: Grading, rows: list[int]) -> list[int]:
    if grading.force_positions is None:
        return rows
    outside = [k for k in grading.force_positions if k not in rows]
    if outside:
        raise InputError(f"[template.grading] force_positions: {outside} are not table positions (1 .. {rows[-1]})")
    return sorted(grading.force_positions)


def _items(quantities: list[_Quantity], grading: Grading,
           notes: list[str]) -> tuple[list[KeyItem], list[int]]:
    """Floors per family (the largest magnitude of the family's values and scales), round-off
    below :data:`~linkage.report.tables.TABLE_ZERO` of the floor written as 0, tolerances and
    digits; non-finite values (positions that failed) left out, and the optional quantities (the
    components of a point's analogs, velocity and acceleration) that are 0 at every position."""
    floors: dict[str, float] = {}
    for q in quantities:
        values = [abs(v) for v in q.values.values() if math.isfinite(v)]
        if q.scale is not None:
            values += [float(v) for v in np.abs(q.scale) if math.isfinite(v)]
        floors[q.family] = max([floors.get(q.family, 0.0), *values])
    items, skipped, zero = [], set(), []
    for q in quantities:
        floor = floors[q.family]
        tolerance = grading.tolerance_of(q.name)
        cleaned = {position: 0.0 if abs(value) <= TABLE_ZERO * floor else value + 0.0
                   for position, value in q.values.items()}
        if q.optional and all(v == 0 for v in cleaned.values()):
            zero.append(q.name)
            continue
        for position, value in cleaned.items():
            if not math.isfinite(value):
                skipped.add(position)
                continue
            other = (q.other or {}).get(position)
            other = other + 0.0 if other is not None and math.isfinite(other) else None
            items.append(KeyItem(q.name, position, value, q.unit, tolerance, grading.digits, floor, other))
    if zero:
        notes.append(f"{', '.join(zero)}: 0 at every position (that coordinate of the point does not change), "
                     "left out")
    return items, sorted(p for p in skipped if p is not None)
