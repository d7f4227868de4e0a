"""The tables of ``linkage analyze``, ``linkage forces`` and ``linkage dynamics`` as data: one
function per command computes them for the command line, the report folder and the answer keys of
course variants, so all three say the same numbers. Each returns the columns, the metadata of the
JSON document and the notes and warnings to say (the command line prints them on stderr).

>>> import linkage
>>> results = dynamics_results(linkage.load("course_slider_crank"))
>>> results.summary["scheme"], results.summary["method"], len(results.columns["omega"])
('course_slider_crank', 'course', 13)
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from assur.base import CANNOT_ASSEMBLE, NOT_CONVERGED, SINGULAR

from ..dynamics.pipeline import DynamicsReport, run_dynamics
from ..errors import InputError
from ..kinematics.extremes import table_angles
from ..kinematics.motion import Motion, analyze, position_column, table_positions_deg
from ..kinetostatics.efficiency import CycleWorks, cycle_works
from ..kinetostatics.reactions import solve_reactions, virtual_power_residual
from ..model.mechanism import Mechanism
from ..model.scheme import section_of
from ..structure import structure_of
from .tables import format_columns, per_turned_angle, units_of

__all__ = ["ANALOGS_PER_TURNED", "ANALOGS_PER_SLIDE", "JSON_CONVENTIONS", "DynamicsResults", "InputRange",
           "TableResults", "analog_direction", "declared_rotation", "dynamics_results", "failures",
           "forces_results", "json_document", "kinematics_results", "table_positions"]

#: the ``conventions`` entry of every JSON document the command line writes
JSON_CONVENTIONS = "see `linkage --help` and docs/conventions.md"


@dataclass(frozen=True)
class DynamicsResults:
    """What ``linkage dynamics`` reports: the per-position ``columns`` (see
    :meth:`DynamicsReport.columns`), the scalar ``summary`` (``scheme``, ``positions``,
    ``phi0_deg``, ``direction``, then :meth:`DynamicsReport.summary`) and the ``report`` they
    come from (its ``notes`` say what the numbers assume)."""

    report: DynamicsReport
    columns: dict[str, np.ndarray]
    summary: dict[str, Any]

    def json(self) -> str:
        """The JSON document of ``linkage dynamics SCHEME --format json`` (same options)."""
        return json_document(self.columns, self.summary)


def dynamics_results(mech: Mechanism, method: str = "course", *, positions: int | None = None,
                     delta: float | None = None, mean_speed: float | None = None,
                     friction: bool = False, real_speed: bool = False) -> DynamicsResults:
    """Run :func:`linkage.dynamics.pipeline.run_dynamics` and arrange its results as ``linkage dynamics``
    prints them (arguments and errors as there)."""
    report = run_dynamics(mech, method, positions=positions, delta=delta, mean_speed=mean_speed, friction=friction,
                          real_speed=real_speed)
    law = report.law
    summary = {"scheme": mech.name, "positions": len(law.phi) - 1, "phi0_deg": float(np.degrees(law.phi[0])),
               "direction": law.reduced.rotation, **report.summary()}
    return DynamicsResults(report, report.columns(), summary)


def json_document(columns: dict[str, Any], meta: dict[str, Any]) -> str:
    """A table as the command line's JSON: ``meta``, ``conventions``, ``units`` and ``rows``."""
    return format_columns(columns, "json", meta={**meta, "conventions": JSON_CONVENTIONS},
                          units=units_of(columns))


#: the convention of the reaction columns of ``linkage forces``
REACTION_CONVENTION = "K.R, K.angle_deg: the force R[a, b] that link b exerts on link a (pair links = [a, b])"


@dataclass(frozen=True)
class InputRange:
    """A table over the input angles ``a .. b`` (deg) instead of a turn (``--range A B``)."""

    a: float
    b: float

    @property
    def span(self) -> tuple[float, float]:
        """The range in rad."""
        return math.radians(self.a), math.radians(self.b)

    def __repr__(self) -> str:
        return f"--range {self.a:g} {self.b:g}"


@dataclass(frozen=True)
class TableResults:
    """A table of ``linkage analyze`` or ``linkage forces``: ``columns``, the JSON metadata
    ``meta`` (scheme, positions, start, phi0_deg, direction, failed ...), the ``motion`` analysed,
    the ``notes`` and ``warnings`` to say to the user (one line each) and, for ``linkage forces``,
    the :class:`~linkage.kinetostatics.reactions.Reactions` the columns come from and, with
    friction, the :class:`~linkage.kinetostatics.efficiency.CycleWorks` of ``meta["cycle"]``."""

    columns: dict[str, np.ndarray]
    meta: dict[str, Any]
    motion: Motion
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    reactions: Any = None
    cycle: Any = None

    def json(self) -> str:
        """The JSON document of the command (every column)."""
        return json_document(self.columns, self.meta)


def declared_rotation(mech: Mechanism) -> int:
    """The order of table positions: the sign of the scheme's declared mean speed, else +1."""
    spec = section_of(mech, "dynamics")
    return spec.rotation if spec is not None else 1


def table_defaults(mech: Mechanism, positions: int | None = None,
                   start: str | float | InputRange | None = None) -> tuple[int, str | float | InputRange]:
    """The number of positions and the start of a table: the given ones, else the scheme's
    [dynamics] positions and start_deg, else 12 positions from the output's extreme position."""
    spec = section_of(mech, "dynamics")
    n = positions if positions is not None else spec.positions if spec is not None else 12
    start = start if start is not None else spec.start if spec is not None else "extreme"
    return n, start


def table_positions(mech: Mechanism, n: int, start: str | float | InputRange, direction: int,
                    notes: list[str] | None = None) -> tuple[np.ndarray, str | float]:
    """Input angles of a table (rad) and the start actually used ("range" over an input range:
    an :class:`InputRange`, else the scheme's range_deg); what was assumed is appended to
    ``notes``."""
    if not mech.coordinate.is_angle and isinstance(start, InputRange):
        raise InputError(f"{start!r}: scheme '{mech.name}' is driven by a slide (input '{mech.inputs[0]}'), "
                         "analysed over the stroke it declares (range = [s_start, s_end] in m); --range A B "
                         "gives input angles (deg) for a crank")
    if isinstance(start, InputRange) or mech.input_range is not None:
        if not (start is None or start == "extreme" or isinstance(start, InputRange)):
            other = ("choose another range with --range A B" if mech.coordinate.is_angle else
                     "a slide input is analysed over its stroke: declare another one with range = [s_start, s_end] "
                     "in the scheme")
            raise InputError(f"scheme '{mech.name}' declares {declared_range(mech)}, which fixes position 1 at "
                             f"{_shown(mech, mech.input_range[0])}: --start {start} applies to a full turn of a "
                             f"crank ({other})")
        span = start.span if isinstance(start, InputRange) else None
        return table_angles(mech, n, "extreme", direction, span=span), "range"
    if isinstance(start, str) and mech.output is None:
        if notes is not None:
            notes.append(f"scheme '{mech.name}' declares no output, so it has no extreme position: the table "
                         "starts at phi = 0 deg (use --start DEG to choose)")
        start = 0.0
    try:
        return table_angles(mech, n, start, direction), start
    except InputError as exc:  # e.g. the output has no extreme position
        if isinstance(start, str):
            raise InputError(f"{exc} (choose position 1 with --start DEG)") from None
        raise


def declared_range(mech: Mechanism) -> str:
    """The scheme's input range as it is written: ``range_deg = [a, b]`` for a crank's angles
    (deg), ``range = [a, b] m`` for a slide input's stroke."""
    a, b = mech.coordinate.shown(mech.input_range)
    return f"range_deg = [{a:.10g}, {b:.10g}]" if mech.coordinate.is_angle else f"range = [{a:.10g}, {b:.10g}] m"


def _shown(mech: Mechanism, value: float) -> str:
    """One value of the input coordinate with its unit: ``27.5 deg`` or ``0.48 m``."""
    return f"{float(mech.coordinate.shown(value)):.10g} {mech.coordinate.shown_unit}"


def start_meta(mech: Mechanism, phi: np.ndarray) -> dict[str, float]:
    """The position-1 entry of a JSON document: ``phi0_deg`` (the input angle, deg) for a crank,
    ``s0`` (the input slide, m) for a slide input."""
    if mech.coordinate.is_angle:
        return {"phi0_deg": float(np.degrees(phi[0]))}
    return {"s0": float(phi[0])}


def table_sense(phi: np.ndarray) -> int:
    """+1 / -1: the sense in which a table's input angles run (``phi = phi0 + direction * phi_deg``)."""
    return -1 if len(phi) > 1 and phi[-1] < phi[0] else 1


def analog_direction(mech: Mechanism, phi: np.ndarray) -> int:
    """The factor that turns a table's first analogs d/dphi (the Python API's) into the analogs
    for people, d/dpsi (:func:`~linkage.report.tables.per_turned_angle`): the sense of the table
    (:func:`table_sense`) for a crank, whose psi is the angle turned from position 1 (the
    ``phi_deg`` column, in rad); +1 for a slide input, whose analogs are per m of the slide ``s``
    itself (a coordinate has no sense of rotation)."""
    return table_sense(phi) if mech.coordinate.is_angle else 1


#: the ``analogs`` entry of the JSON document of ``linkage analyze`` for a crank (docs/conventions.md)
ANALOGS_PER_TURNED = ("d/dpsi: per rad turned in the direction of rotation from position 1 "
                      "(psi = phi_deg in rad; the Python API's Motion gives d/dphi)")
#: the same for a slide input: its analogs are per m of the slide ``s``
ANALOGS_PER_SLIDE = "d/ds: per m of the input's slide s (the position column)"


def failures(motion: Motion) -> tuple[list[dict], list[str]]:
    """The positions of ``motion`` that cannot be assembled, are singular or where Newton's method
    did not converge (a group solved by it, docs/groups.md): one JSON entry per
    position (``position``, ``phi_deg``, ``input_angle_deg``, ``problem``; for a singular one the
    least conditioned ``group`` and its ``conditioning``) and one warning line per problem."""

    failed, lines = [], []
    mech = motion.mechanism
    angle = mech.coordinate.is_angle
    column = position_column(mech)
    travelled = table_positions_deg(motion.phi) if angle else np.asarray(motion.phi, float)
    phi_deg = np.degrees(motion.phi) if angle else np.asarray(motion.phi, float)
    where_words = "input angle phi = {} deg" if angle else "input slide s = {} m"
    for code, what, blank in ((CANNOT_ASSEMBLE, "cannot be assembled", "values are empty (nan)"),
                              (SINGULAR, "is singular", "analogs are empty (nan)"),
                              (NOT_CONVERGED, "was not solved: Newton's method did not converge",
                               "values are empty (nan)")):
        where = np.flatnonzero(motion.status == code)
        if not len(where):
            continue
        numbers = ", ".join(str(i + 1) for i in where)
        shown = ", ".join(f"{phi_deg[i]:.6g}" for i in where)
        lines.append(f"mechanism '{motion.mechanism.name}' {what} at positions i = {numbers} "
                     f"({where_words.format(shown)}): {blank} in those rows")
        for i in where:
            entry = {"position": int(i) + 1, column: float(travelled[i])}
            if angle:
                entry["input_angle_deg"] = float(phi_deg[i])
            entry["problem"] = what
            if code == SINGULAR:  # the least conditioned group: its distance to the singularity
                worst = min(motion.conditioning.items(), key=lambda kv: np.nan_to_num(kv[1][i], nan=2.0))
                entry.update(group=worst[0], conditioning=float(worst[1][i]))
            failed.append(entry)
    failed.sort(key=lambda f: f["position"])
    return failed, lines


#: a floating-point warning of numpy (overflow, invalid value ...) in the library's words
NUMERICAL_WARNING = ("a floating-point overflow or invalid value occurred in the computation: check the "
                     "results")


def _caught(caught, failed) -> list[str]:
    """The warnings recorded during an analysis, as lines: the library's as they are, numpy's
    floating-point warnings as :data:`NUMERICAL_WARNING` (left out when positions were already
    reported as failed: they are the noise of those positions)."""
    lines = [str(w.message) for w in caught if not issubclass(w.category, RuntimeWarning)]
    if not failed and any(issubclass(w.category, RuntimeWarning) for w in caught):
        lines.append(NUMERICAL_WARNING)
    return lines


def kinematics_results(mech: Mechanism, positions: int | None = None,
                       start: str | float | InputRange | None = None) -> TableResults:
    """The table of ``linkage analyze``: positions and analogs at the scheme's table positions
    (``positions`` and ``start`` as the command's options).

    The table is for people: its first analogs are taken with respect to the angle turned, psi
    (``phi_deg`` in rad), ``B.x' = dx_B/dpsi = direction * dx_B/dphi`` (:func:`analog_direction`,
    :func:`~linkage.report.tables.per_turned_angle`); second analogs are the same either way.
    ``motion`` (the :class:`~linkage.kinematics.motion.Motion`) keeps d/dphi; the JSON metadata
    says so under ``analogs``."""
    direction = declared_rotation(mech)
    n, start = table_defaults(mech, positions, start)
    notes: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        phi, start = table_positions(mech, n, start, direction, notes)
        motion = analyze(mech, phi, order=2, on_failure="mask")
        columns = per_turned_angle(motion.columns(), analog_direction(mech, phi))
    failed, lines = failures(motion)
    meta = {"scheme": mech.name, "description": mech.description, "formula": structure_of(mech).formula,
            "positions": n, "start": start, **start_meta(mech, phi), "direction": table_sense(phi),
            "analogs": ANALOGS_PER_TURNED if mech.coordinate.is_angle else ANALOGS_PER_SLIDE,
            "failed": failed}
    return TableResults(columns, meta, motion, notes, lines + _caught(caught, failed))


def forces_results(mech: Mechanism, positions: int | None = None, start: str | float | InputRange | None = None,
                   omega: float | None = None, eps: float = 0.0, friction: bool = False) -> TableResults:
    """The table of ``linkage forces``: reactions and the balancing moment at the scheme's table
    positions, at the input speed ``omega`` (rad/s, signed; default the scheme's mean speed, else
    a static analysis) and acceleration ``eps`` (rad/s^2); with ``friction`` the scheme's
    ``[friction]`` in the pairs (the losses per pair, the efficiency per position and, for a crank
    that turns fully, the works and the efficiency of one turn at constant speed in
    ``meta["cycle"]``)."""

    notes: list[str] = []
    spec = section_of(mech, "dynamics")
    if omega is None and spec is not None:
        omega = spec.mean_speed
    if omega is None and eps != 0:
        notes.append("no speed given: omega = 0 with the given eps")
        omega = 0.0
    direction = declared_rotation(mech) if not omega else int(np.sign(omega))
    n, start = table_defaults(mech, positions, start)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        phi, start = table_positions(mech, n, start, direction, notes)
        motion = analyze(mech, phi, order=2, omega=omega, eps=eps, on_failure="mask")
        ends = np.zeros(len(phi), bool)
        ends[-1] = True
        # a static analysis: the friction opposes the table's own travel (a slide's stroke may run down)
        travel = direction if mech.coordinate.is_angle else (1 if phi[-1] >= phi[0] else -1)
        reactions = solve_reactions(motion, ends=ends, friction=friction, sense=travel)
        residual = virtual_power_residual(reactions)
        cycle = friction_cycle(mech, omega, notes) if friction else None
    failed, lines = failures(motion)
    notes += list(reactions.notes)
    meta = {"scheme": mech.name, "formula": structure_of(mech).formula, "omega": omega, "eps": eps,
            "positions": n, "start": start, **start_meta(mech, phi), "direction": table_sense(phi),
            "convention": REACTION_CONVENTION,
            "virtual_power_residual_max": float(np.nanmax(residual)) if np.isfinite(residual).any() else None,
            "failed": failed, "notes": list(reactions.notes)}
    if friction:
        meta["friction"] = {name: {k: v for k, v in (("kind", p.kind), ("f", p.f), ("radius", p.radius),
                                                      ("length", p.length)) if v is not None}
                            for name, p in reactions.friction.pairs.items()}
        meta["self_locking_positions"] = [int(i) + 1 for i in np.flatnonzero(reactions.locked)]
        if motion.omega is None:
            notes.append("static analysis: the friction opposes the input's "
                         f"{'increasing' if travel > 0 else 'decreasing'} coordinate; power_lost and K.power_lost "
                         "are per unit of its speed (W per rad/s, i.e. N m; W per m/s for a slide input)")
        meta["cycle"] = _cycle_meta(cycle)
    return TableResults(_friction_first(reactions.columns(full=True)), meta, motion, notes,
                        lines + _caught(caught, failed), reactions, cycle)


def _friction_first(columns: dict) -> dict:
    """The columns with ``efficiency`` and ``power_lost`` right after the balancing load."""
    order = list(columns)
    for name in ("power_lost", "efficiency"):
        if name in columns:
            order.remove(name)
            at = next(i for i, k in enumerate(order) if k.startswith("balancing_")) + 1
            order.insert(at, name)
    return {k: columns[k] for k in order}


def friction_cycle(mech: Mechanism, omega: float | None, notes: list[str]) -> CycleWorks | None:
    """The works of one turn with friction at constant speed (``cycle_works``), None (with a
    note) where the input is not a crank turning fully."""
    try:
        return cycle_works(mech, omega, friction=True)
    except InputError as exc:
        notes.append(f"no cycle efficiency: {exc}")
        return None


def _cycle_meta(works: CycleWorks | None) -> dict | None:
    """The table's ``meta["cycle"]``: the works of one turn, J."""
    if works is None:
        return None
    return {"driving_work": works.driving + 0.0, "useful_work": works.useful + 0.0,
            "friction_work": works.friction + 0.0, "efficiency": works.efficiency + 0.0, "samples": works.samples,
            "locked_samples": works.locked, "omega": works.omega, "unit": "J"}
