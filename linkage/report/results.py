"""The results of ``linkage dynamics`` as data: one function computes them for the command line,
the report folder and the answer keys of course variants, so all three say the same numbers.

>>> import linkage
>>> results = dynamics_results(linkage.load("course_slider_crank"))
>>> results.summary["scheme"], results.summary["method"], len(results.columns["omega"])
('course_slider_crank', 'course', 13)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..dynamics import DynamicsReport, run_dynamics
from ..model import Mechanism
from .tables import format_columns, units_of

__all__ = ["DynamicsResults", "dynamics_results", "JSON_CONVENTIONS", "json_document"]

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
                     delta: float | None = None, mean_speed: float | None = None) -> DynamicsResults:
    """Run :func:`linkage.dynamics.run_dynamics` and arrange its results as ``linkage dynamics``
    prints them (arguments and errors as there)."""
    report = run_dynamics(mech, method, positions=positions, delta=delta, mean_speed=mean_speed)
    law = report.law
    summary = {"scheme": mech.name, "positions": len(law.phi) - 1, "phi0_deg": float(np.degrees(law.phi[0])),
               "direction": law.reduced.rotation, **report.summary()}
    return DynamicsResults(report, report.columns(), summary)


def json_document(columns: dict[str, Any], meta: dict[str, Any]) -> str:
    """A table as the command line's JSON: ``meta``, ``conventions``, ``units`` and ``rows``."""
    return format_columns(columns, "json", meta={**meta, "conventions": JSON_CONVENTIONS},
                          units=units_of(columns))
