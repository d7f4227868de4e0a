"""The numbers of a course project's kinematics sheet: the table, the chosen position's plans,
and a dense sweep for the diagrams (:func:`kinematics_data`, a :class:`KinematicsData`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from assur.base import OK

from ...errors import InputError
from ...kinematics.extremes import extreme_positions
from ...kinematics.motion import Motion, analyze
from ...kinetostatics.plans import Plans, build_plans
from ...model.mechanism import Mechanism
from ...model.scheme import section_of
from ...report.results import TableResults, kinematics_results

__all__ = ["DIAGRAM_SAMPLES", "KinematicsData", "kinematics_data"]

#: samples of the diagrams per table step
DIAGRAM_SAMPLES = 16


@dataclass
class KinematicsData:
    """What the sheet draws: the table (``results``, as ``linkage analyze``), the chosen row
    ``index``, the rows drawn as positions, the input speed ``omega`` (rad/s) the plans are at,
    the ``plans`` (None for a slide input), the dense ``sweep`` over the table's travel for the
    diagrams, with its turned coordinate ``psi`` (rad; m for a slide input) and the rows of the
    output's extremes in it, and the ``notes`` the sheet states."""

    mech: Mechanism
    results: TableResults
    index: int
    rows: list[int]
    omega: float
    plans: Plans | None
    sweep: Motion
    psi: np.ndarray
    extremes: dict[str, int]
    notes: list[str] = field(default_factory=list)

    @property
    def motion(self) -> Motion:
        return self.results.motion


def kinematics_data(mech: Mechanism, position: int) -> KinematicsData:
    """The numbers of the sheet at the table position ``position`` (1-based, as ``linkage plans
    --position``). Raises InputError for a position outside the table or one that does not
    assemble."""
    results = kinematics_results(mech)
    motion = results.motion
    count = len(motion.phi)
    if isinstance(position, bool) or not isinstance(position, (int, np.integer)) or not 1 <= position <= count:
        raise InputError(f"position {position!r}: scheme '{mech.name}' has the table positions 1 to {count}")
    i = int(position) - 1
    if motion.status[i] != OK:
        raise InputError(f"position {position}: scheme '{mech.name}' does not assemble there "
                         f"({mech.coordinate.describe([motion.phi[i]])}): choose another position")
    full_turn = mech.coordinate.is_angle and mech.input_range is None
    rows = [k for k in range(count - 1 if full_turn else count) if motion.status[k] == OK]
    notes = list(results.notes)
    spec = section_of(mech, "dynamics")
    omega = spec.mean_speed if spec is not None and spec.mean_speed else None
    plans = None
    if not mech.coordinate.is_angle:
        notes.append("the plans of velocities and accelerations are built for a crank input only; this scheme is "
                     "driven by a slide, so the sheet has the diagrams of the analogs per m of the slide instead")
    else:
        if omega is None:
            omega = 1.0
            notes.append("the scheme declares no speed: the plans are drawn at ω₁ = 1 rad/s (the analogs, "
                         "in m/s per rad/s)")
        at = analyze(mech, motion.phi[i:i + 1], order=2, omega=omega, eps=0.0)
        plans = build_plans(at)
    sweep, psi, extremes = _sweep(mech, motion.phi)
    return KinematicsData(mech, results, i, rows, omega or 0.0, plans, sweep, psi, extremes, notes)


def _sweep(mech: Mechanism, phi: np.ndarray) -> tuple[Motion, np.ndarray, dict[str, int]]:
    """The motion over the table's travel at :data:`DIAGRAM_SAMPLES` per step, with the
    output's extreme positions among its rows; the turned coordinate psi of each row."""
    steps = len(phi) - 1
    travel = float(phi[-1] - phi[0])
    t = np.linspace(0.0, 1.0, steps * DIAGRAM_SAMPLES + 1)
    wanted: dict[str, float] = {}
    if mech.output is not None:
        try:
            ext = extreme_positions(mech)
        except InputError:
            ext = None
        if ext is not None and ext.moves(mech.size):
            for key, angle in (("max", ext.phi_max), ("min", ext.phi_min)):
                frac = (angle - phi[0]) / travel
                if mech.coordinate.is_angle and mech.input_range is None:
                    frac = ((angle - phi[0]) * np.sign(travel)) % (2 * np.pi) / abs(travel)
                if -1e-12 <= frac <= 1 + 1e-12:
                    wanted[key] = float(np.clip(frac, 0.0, 1.0))
    t = np.unique(np.concatenate([t, list(wanted.values())]))
    sweep = analyze(mech, phi[0] + travel * t, order=2, on_failure="mask")
    psi = np.abs(travel) * t if mech.coordinate.is_angle else phi[0] + travel * t
    rows = {key: int(np.argmin(np.abs(t - frac))) for key, frac in wanted.items()}
    return sweep, psi, rows
