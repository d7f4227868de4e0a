"""A complete analysis folder of one scheme (``linkage report SCHEME --out DIR``).

The folder holds, for machines, the CSV tables of ``linkage analyze``, ``linkage forces`` and
(with a [dynamics] section) ``linkage dynamics`` and its JSON; for people, ``index.html`` (the
scheme's data, its structural formula, the results and every picture inline, written with a
Jinja2 template), the pictures in PNG and SVG and ``animation.gif``, a film of one revolution.
A picture the scheme's data does not allow (no [dynamics] section: no flywheel; no motor: no
start-up; no loads and no masses: no hodographs) is left out with a note saying why; the page
lists the notes too. With ``friction=True`` (``--friction``) the forces and the dynamics include
the scheme's [friction], ``friction.csv`` holds the losses and the efficiency per position, and
``friction.png``/``.svg`` draws them (docs/friction.md).

Needs the ``report`` extra (matplotlib, Jinja2, tqdm): ``pip install "linkage[report]"``.
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from assur.base import OK

from ..errors import InputError, LinkageError
from ..kinetostatics.friction import friction_of
from ..model.mechanism import Mechanism, Prismatic
from ..model.scheme import dumps, section_of
from ..structure import structure_of
from ..version import __version__
from . import machine
from .animation import write_animation
from .diagrams import plot_columns, plot_dynamics, plot_motion
from .drawing import draw_mechanism, draw_positions
from .friction_plots import plot_friction
from .hodographs import plot_hodographs
from .resistance import plot_resistance, resistance_curves
from .results import dynamics_results, forces_results, kinematics_results
from .tables import format_columns, units_of
from .words import link_role, speed_words

__all__ = ["ReportExtraMissing", "Report", "write_report", "REPORT_EXTRA"]

#: the libraries the report needs (import name -> distribution), all in the ``report`` extra
REPORT_EXTRA = {"matplotlib": "matplotlib", "jinja2": "Jinja2", "tqdm": "tqdm"}

#: resolution of the PNG pictures, dots per inch (the figures are sized for A4 text width)
DPI = 150


class ReportExtraMissing(LinkageError, ImportError):
    """A library of the ``report`` extra is not installed."""


def require_report_extra(what: str = "linkage report") -> None:
    """Raise :class:`ReportExtraMissing` naming what to install when a library of the
    ``report`` extra is missing."""
    missing = [dist for module, dist in REPORT_EXTRA.items() if importlib.util.find_spec(module) is None]
    if missing:
        raise ReportExtraMissing(f"{what} needs the 'report' extra ({', '.join(missing)} missing): "
                                 "pip install \"linkage[report]\"")


@dataclass
class Report:
    """What :func:`write_report` wrote: the folder, the files in the order written, and the
    notes on pictures or tables left out."""

    folder: Path
    files: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    pictures: list[dict[str, str]] = field(default_factory=list)


def write_report(mech: Mechanism, out: str | Path, *,
                 progress: Callable[[Iterable, int], Iterable] | None = None, frames: int = 72,
                 friction: bool = False) -> Report:
    """Write the analysis folder of ``mech`` into ``out`` (created; files of the same names are
    replaced).

    Parameters
    ----------
    mech : Mechanism
    out : path
    progress : callable, optional
        ``progress(steps, total)`` wraps the list of steps (a progress bar).
    frames : int
        Frames of the animation over one revolution (or over the input range).
    friction : bool
        Include the scheme's ``[friction]`` in the forces and the dynamics, and write the friction
        table (``friction.csv``) and picture (``friction.png``, ``.svg``).

    Returns
    -------
    Report

    Raises
    ------
    InputError
        ``friction`` for a scheme without a ``[friction]`` section (before anything is written).
    """
    require_report_extra()
    if friction and friction_of(mech) is None:
        raise InputError(f"--friction: scheme '{mech.name}' declares no [friction] section: add one "
                         "(docs/friction.md), e.g. [friction] revolute = { f = 0.1, radius = 0.02 } and "
                         "prismatic = { f = 0.15 }")
    import matplotlib

    matplotlib.use("Agg")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file, not a folder")
    out.mkdir(parents=True, exist_ok=True)
    report = Report(out)
    work = _Work(mech, report, friction)
    steps = work.steps()
    for step in (progress(steps, len(steps)) if progress is not None else steps):
        step()
    work.page()
    return report


class _Work:
    """The steps of a report, each a method that writes its files (so a progress bar can count
    them), and the data the page shows."""

    def __init__(self, mech: Mechanism, report: Report, friction: bool = False):
        self.mech, self.report, self.friction = mech, report, friction
        self.kinematics = self.forces = self.dynamics = None
        self.spec = section_of(mech, "dynamics")

    def steps(self) -> list[Callable[[], None]]:
        steps = [self.tables, self.mechanism_pictures, self.kinematic_diagrams, self.force_pictures]
        if self.friction:
            steps.append(self.friction_picture)
        if self.spec is not None:
            steps += [self.dynamics_tables, self.machine_pictures, self.startup]
        elif not self.mech.coordinate.is_angle:
            self.report.notes.append("dynamics: left out (a slide input moves over one stroke, not a cycle: its law "
                                     f"of motion under an actuator's force is `linkage dynamics {self.mech.name} "
                                     "--force N`)")
        else:
            self.report.notes.append("dynamics (reduced moments, flywheel, law of motion, start-up): left out "
                                     "(the scheme declares no [dynamics] section)")
        steps.append(self.animation)
        return steps

    # files -------------------------------------------------------------------------------------

    def _write(self, name: str, content: str | bytes) -> None:
        path = self.report.folder / name
        path.write_bytes(content.encode() if isinstance(content, str) else content)
        self.report.files.append(name)

    def _picture(self, name: str, title: str, build: Callable[[], Any]) -> None:
        """Save the figure ``build()`` returns as ``name``.png and .svg; a LinkageError (what the
        picture needs is missing, or its computation fails: no steady state, a run-away) becomes a
        note, and the report goes on with its other parts."""
        import matplotlib.pyplot as plt

        try:
            fig = build()
        except LinkageError as exc:
            self.report.notes.append(f"{title}: left out ({exc})")
            return
        fig = getattr(fig, "figure", fig)  # an Axes -> its Figure
        try:
            fig.savefig(self.report.folder / f"{name}.png", dpi=DPI, metadata={"Software": None})
            fig.savefig(self.report.folder / f"{name}.svg", metadata={"Date": None})
        finally:
            plt.close(fig)
        self.report.files += [f"{name}.png", f"{name}.svg"]
        self.report.pictures.append({"name": name, "title": title})

    # steps -------------------------------------------------------------------------------------

    def tables(self) -> None:
        self.kinematics = kinematics_results(self.mech)
        self.forces = forces_results(self.mech, friction=self.friction)
        for results in (self.kinematics, self.forces):
            self.report.notes += results.notes + results.warnings
        self._write("scheme.toml", dumps(self.mech))
        self._write("kinematics.csv", format_columns(self.kinematics.columns, "csv"))
        self._write("kinematics.json", self.kinematics.json())
        self._write("forces.csv", format_columns(self.forces.columns, "csv"))
        self._write("forces.json", self.forces.json())
        if self.friction:
            self._friction_table()

    def _friction_table(self) -> None:
        """``friction.csv``: the balancing load, the efficiency and the losses per position; the
        works of one turn at constant speed as a note (forces.json, key ``cycle``)."""
        columns = self.forces.columns
        names = [n for n in columns if n in ("i", "phi_deg", "s", "efficiency", "power_lost")
                 or n.startswith("balancing_") or n.endswith((".Mf", ".Ff", ".power_lost"))]
        self._write("friction.csv", format_columns({n: columns[n] for n in names}, "csv"))
        cycle = self.forces.meta.get("cycle")
        if cycle:
            self.report.notes.append(
                f"friction: one turn at constant speed ({cycle['samples']} steps): driving work "
                f"{cycle['driving_work']:.6g} {cycle['unit']}, useful work {cycle['useful_work']:.6g}, work lost to "
                f"friction {cycle['friction_work']:.6g}; cycle efficiency {cycle['efficiency']:.4f} "
                "(forces.json, key cycle)")

    def _trajectories(self) -> list[str]:
        """The output point's path, drawn on the mechanism's pictures and the film."""
        return [self.mech.output_point] if self.mech.output_point is not None else []

    def mechanism_pictures(self) -> None:

        motion = self.kinematics.motion
        ok = np.flatnonzero(motion.status == OK)
        if not len(ok):
            self.report.notes.append("the mechanism drawings: left out (no position of the table assembles)")
            return
        trajectories = self._trajectories()
        self._picture("mechanism", "The mechanism at position 1, to scale",
                      lambda: draw_mechanism(motion, int(ok[0]), trajectories=trajectories))
        if self.mech.input_range is None and len(ok) > 1:
            ok = ok[ok < len(motion.phi) - 1]  # over a turn the last row is position 1 again
        spread = [int(i) for i in ok[(np.arange(min(4, len(ok))) * len(ok)) // min(4, len(ok))]]
        self._picture("positions", "The mechanism at four table positions, at one scale",
                      lambda: draw_positions(motion, sorted(set(spread)), trajectories=trajectories))

    def kinematic_diagrams(self) -> None:

        output = self.mech.output
        if output is None:
            self.report.notes.append("kinematic diagrams: left out (the scheme declares no output)")
            return
        q = output.quantity
        per = ("per rad of crank rotation, d/dψ" if self.mech.coordinate.is_angle
               else "per m of the input's slide, d/ds")
        self._picture("kinematic_diagrams", f"Kinematic diagrams of the output {q}: position and analogs ({per})",
                      lambda: plot_motion(self.kinematics.motion, [q, q + "'", q + "''"]))

    def force_pictures(self) -> None:

        columns = self.forces.columns
        # a crank is balanced by a moment (N m), a slide input by a force (N)
        load = "moment" if self.mech.coordinate.is_angle else "force"
        moment = np.asarray(columns[f"balancing_{load}"], dtype=float)
        if not np.any(np.nan_to_num(moment)):
            self.report.notes.append(f"balancing {load} and hodographs: left out (the scheme declares no loads "
                                     "and no masses: every reaction is zero)")
            return

        def balancing():
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(7.5, 3.4), layout="constrained")
            plot_columns(columns, [name for name in columns if name.startswith(f"balancing_{load}")], ax,
                         mechanism=self.mech)
            return fig

        who = "input link" if load == "moment" else "input slide"
        self._picture(f"balancing_{load}", f"Balancing {load} on the {who}"
                      + ("s" if len(self.mech.inputs) > 1 else "")
                      + f" ({self._speed_note()}{', with friction in the pairs' if self.friction else ''})",
                      balancing)
        self._picture("hodographs", "Hodographs of the reactions in the main pairs",
                      lambda: plot_hodographs(self.forces.reactions))

    def friction_picture(self) -> None:

        reactions = self.forces.reactions
        self._picture("friction", f"Friction in the pairs: the power lost in each pair and the efficiency η "
                                  f"({self._speed_note()})",
                      lambda: plot_friction(reactions, reactions.motion.direction, cycle=self.forces.cycle))

    def _speed_note(self) -> str:
        """At what speed the forces were found: a static case says so."""
        words = speed_words(self.forces.reactions.motion)
        return "static: no speed given, no inertia forces" if words.startswith("no speed") else f"kinetostatics {words}"

    def dynamics_tables(self) -> None:
        try:
            self.dynamics = dynamics_results(self.mech, friction=self.friction)
        except LinkageError as exc:
            self.report.notes.append(f"dynamics: left out ({exc})")
            return
        self.report.notes += list(self.dynamics.report.notes)
        self._write("dynamics.csv", format_columns(self.dynamics.columns, "csv"))
        self._write("dynamics.json", self.dynamics.json())

    def machine_pictures(self) -> None:

        if self.dynamics is None:
            return
        report = self.dynamics.report
        self._picture("moments_and_work", "Reduced moments and the work of the forces",
                      lambda: machine.plot_moments_and_work(report))
        self._picture("energy_inertia", "Energy–inertia diagram (Wittenbauer)",
                      lambda: machine.plot_energy_inertia(report))
        self._picture("flywheel_energy", "Energy change of the flywheel ΔT' and the flywheel (Mertsalov)",
                      lambda: machine.plot_flywheel_energy(report))
        self._picture("speed_two_ways", "Angular velocity and acceleration of the crank, two ways",
                      lambda: machine.plot_speed_two_ways(report))
        self._picture("law_of_motion", "Law of motion and balancing moment under the real motion",
                      lambda: plot_dynamics(report, ["omega", "eps", "balancing_moment"]))
        self._picture("reduced_inertia", "Reduced moment of inertia I_red(φ)",
                      lambda: plot_dynamics(report, ["reduced_inertia"]))
        if resistance_curves(self.kinematics.motion):
            self._picture("resistance", "Useful resistance over the stroke, P(s)",
                          lambda: plot_resistance(self.kinematics.motion))
        self._course_delta(report)

    def _course_delta(self, report) -> None:
        """Say plainly when the course method's flywheel misses δ under the exact solution."""
        law = report.law
        if law.method == "exact" or law.required_constant_inertia is None:
            return
        try:
            omega_m, delta = machine._mean_speed_and_delta(law)
            ode, _ = machine._steady_with_constant_moment(self.mech, law, omega_m, delta)
        except (LinkageError, ValueError, ZeroDivisionError):
            return
        if ode.delta_actual > delta * (1 + 1e-3):
            self.report.notes.append(
                f"the course method's flywheel misses δ: under the exact solution (the equation of motion, "
                f"periodic steady state) it gives δ = {ode.delta_actual:.4g}, not the target {delta:.4g} "
                f"({100 * (ode.delta_actual / delta - 1):.3g} % more); 'linkage dynamics --method ode' sizes "
                "the flywheel for δ exactly")

    def startup(self) -> None:

        if self.spec is None or self.spec.motor is None:
            self.report.notes.append("start-up from several initial speeds: left out (the scheme declares no "
                                     "[dynamics.motor])")
            return
        stalls: list[str] = []  # a start-up that stalls is drawn up to the stall, with a note
        self._picture("startup", "Start-up of the machine from several initial speeds",
                      lambda: machine.plot_startup(self.mech, notes=stalls))
        self.report.notes += stalls

    def animation(self) -> None:

        try:
            write_animation(self.kinematics.motion.mechanism, self.report.folder / "animation.gif",
                            trajectories=self._trajectories())
        except InputError as exc:
            self.report.notes.append(f"animation: left out ({exc})")
            return
        self.report.files.append("animation.gif")

    # the page ----------------------------------------------------------------------------------

    def page(self) -> None:
        import jinja2

        env = jinja2.Environment(loader=jinja2.PackageLoader("linkage.report", "templates"),
                                 autoescape=jinja2.select_autoescape(["html", "j2"]),
                                 undefined=jinja2.StrictUndefined, keep_trailing_newline=True)
        mech = self.mech
        summary = []
        if self.dynamics is not None:
            for key, value in self.dynamics.summary.items():
                if key in _RESULT_WORDS:
                    words, unit = _RESULT_WORDS[key]
                    summary.append({"name": key, "words": words, "value": _number(value), "unit": unit})
        files = self.report.files
        tables = [{"name": n, "kind": "CSV" if n.endswith(".csv") else "JSON"}
                  for n in files if n.endswith((".csv", ".json"))]
        html = env.get_template("report.html.j2").render(
            name=mech.name, description=mech.description, formula=structure_of(mech).formula,
            links=_links(mech), pairs=_pairs(mech), scheme_text=dumps(mech), summary=summary,
            pictures=self.report.pictures, animation="animation.gif" if "animation.gif" in files else None,
            tables=tables, notes=self.report.notes, version=__version__, analogs=_analogs_words(mech),
            kinematics_units=units_of(self.kinematics.columns) if self.kinematics else {}, friction=self.friction)
        self._write("index.html", html)


def _analogs_words(mech: Mechanism) -> str:
    """What the analog columns of kinematics.csv are per, for the page (docs/conventions.md)."""
    if not mech.coordinate.is_angle:
        return ("In kinematics.csv the analogs (the columns ending in ' and '') are per m of the input's "
                "slide s, d/ds.")
    return ("In kinematics.csv the analogs (the columns ending in ' and '') are per rad of crank rotation, "
            "d/dψ and d²/dψ²: ψ is phi_deg in rad, the angle turned from position 1 in the direction of "
            "rotation, so each analog is the slope of its quantity's curve.")


#: the scalar results of ``linkage dynamics`` on the page: key -> (words, unit)
_RESULT_WORDS = {
    "positions": ("table positions per revolution", ""),
    "phi0_deg": ("input angle at position 1", "deg"),
    "direction": ("direction of rotation (+1 counter-clockwise, −1 clockwise)", ""),
    "method": ("method of the law of motion", ""),
    "driving_moment": ("constant driving moment M_d (from the cycle balance)", "N·m"),
    "required_constant_inertia": ("required constant inertia at the crank I' (Mertsalov)", "kg·m²"),
    "flywheel_inertia": ("flywheel inertia I' − I_0 (— : none needed)", "kg·m²"),
    "delta_actual": ("coefficient of speed fluctuation δ of the motion", ""),
    "mean_speed_actual": ("mean angular velocity of the crank ω_m", "rad/s"),
    "dynamic_coefficient": ("coefficient of dynamics max|M_b| / |M_d|", ""),
    "constant_inertia": ("constant inertia at the crank with the flywheel", "kg·m²"),
    "exact_required_constant_inertia": ("required constant inertia, exact energy method", "kg·m²"),
    "exact_flywheel_inertia": ("flywheel inertia, exact energy method", "kg·m²"),
    "course_vs_exact_inertia": ("course / exact required inertia − 1", ""),
    "course_delta_exact": ("δ of the course flywheel, solved exactly", ""),
    "friction_work": ("work lost to friction per cycle (trapezoid over the table positions)", "J"),
    "cycle_efficiency": ("cycle efficiency 1 − A_friction / A_driving (same trapezoid)", ""),
}


def _number(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.6g}" if math.isfinite(value) else "—"
    return str(value)


def _links(mech: Mechanism) -> list[dict[str, str]]:
    """The links as the page lists them: name, role, points (local coordinates, m), mass, J."""

    rows = []
    for name in sorted(mech.links, key=lambda n: (n != mech.frame, n)):
        link = mech.links[name]
        points = ", ".join(f"{p} ({x:.6g}, {y:.6g})" for p, (x, y) in link.points.items())
        rows.append({"name": name, "role": link_role(mech, name), "points": points,
                     "mass": _number(link.mass) if link.mass_declared else "",
                     "inertia": _number(link.inertia) if link.mass_declared else ""})
    return rows


def _pairs(mech: Mechanism) -> list[dict[str, str]]:

    return [{"name": name, "kind": "P (prismatic)" if isinstance(pair, Prismatic) else "R (revolute)",
             "links": " – ".join(pair.links)} for name, pair in sorted(mech.pairs.items())]

