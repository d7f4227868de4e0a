"""The set of a course project's sheets for one mechanism: which can be drawn, in order, numbered.

:func:`project_sheets` composes the kinematics, kinetostatics and dynamics sheets (each from its
own module) for the sheets whose data the scheme holds, numbered k of K; a sheet whose data are
missing is left out with a note naming the key to add. :func:`write_project_sheets` writes them
(:mod:`~.writers`) as ``DIR/SCHEME_kinematics.pdf`` ... in the formats asked.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Sequence

import numpy as np

from ...errors import LinkageError
from ...model.mechanism import Mechanism
from ...report.results import kinematics_results
from .dynamics_sheet import dynamics_sheet
from .frame import TitleInfo, layout_problems
from .kinematics_sheet import kinematics_sheet
from .kinetostatics_sheet import kinetostatics_sheet
from .model import Drawing
from .writers import write

__all__ = ["SHEETS", "drawn_position", "project_sheets", "write_project_sheets"]

#: the sheets of a course project, in order: name and what it shows
SHEETS = (("kinematics", "Kinematic analysis"), ("kinetostatics", "Kinetostatic analysis"),
          ("dynamics", "Machine dynamics"))


def _missing(mech: Mechanism, name: str) -> str | None:
    """Why the sheet ``name`` cannot be drawn from the scheme (the key to add), or None."""
    if name == "kinetostatics" and "loads" not in mech.parts and "dynamics" not in mech.parts:
        return "the scheme declares no [loads] (masses, forces) and no [dynamics] speed: add them to draw the forces"
    if name == "dynamics" and "dynamics" not in mech.parts:
        return "the scheme declares no [dynamics] section (mean speed, delta, the load diagram): add it"
    return None


def drawn_position(mech: Mechanism) -> int:
    """The table position (1-based) the sheets draw by default: where the output moves fastest
    (the largest first analog of the scheme's output among the assembled positions), so that the
    plans and polygons are well proportioned -- position 1 is an extreme position, where the
    output's velocity is 0. Position 1 when the scheme declares no output."""
    if mech.output is None:
        return 1
    results = kinematics_results(mech)
    analog = np.asarray(results.columns.get(f"{mech.output.quantity}'", ()), float)
    ok = results.motion.status == 0
    if not len(analog) or not ok.any():
        return 1
    speed = np.where(ok[:len(analog)], np.abs(analog), -np.inf)
    return int(np.argmax(speed)) + 1


def project_sheets(mech: Mechanism, position: int | None = None, paper: str = "A1", title: TitleInfo | None = None,
                   omega: float | None = None) -> tuple[list[tuple[str, Drawing]], list[str]]:
    """The sheets ``[(name, drawing)]`` of ``mech`` whose data it holds, numbered k of K, and a note
    for each sheet left out.

    Parameters
    ----------
    mech : Mechanism
    position : int, optional
        The table position (1-based) the plans, polygons and groups apart are drawn at (default
        :func:`drawn_position`).
    paper : {"A1", "A2", "A3"}
    title : TitleInfo, optional
        The title block's texts (default: the scheme's name).
    omega : float, optional
        The input's angular velocity for the kinetostatics, rad/s (default: the scheme's mean
        speed).

    Raises
    ------
    LinkageError
        When the kinematics sheet itself cannot be drawn (the mechanism does not move, the
        position does not exist ...).
    """
    title = title or TitleInfo(scheme=mech.name)
    position = drawn_position(mech) if position is None else position
    notes = []
    wanted = []
    for name, what in SHEETS:
        reason = _missing(mech, name)
        if reason is None:
            wanted.append((name, what))
        else:
            notes.append(f"the {name} sheet is left out: {reason}")
    made: list[tuple[str, Drawing]] = []
    for k, (name, _) in enumerate(wanted, start=1):
        numbered = replace(title, number=k, total=len(wanted))
        try:
            if name == "kinematics":
                drawing = kinematics_sheet(mech, position, paper, numbered)
            elif name == "kinetostatics":
                drawing = kinetostatics_sheet(mech, position, paper, numbered, omega=omega)
            else:
                drawing = dynamics_sheet(mech, paper, numbered)
        except LinkageError as exc:
            if name == "kinematics":
                raise
            notes.append(f"the {name} sheet is left out: {exc}")
            continue
        made.append((name, drawing))
    notes += _plans_command(mech, position, dict(made), omega)
    return made, notes


def _plans_command(mech: Mechanism, position: int, made: dict, omega: float | None) -> list[str]:
    """The note giving the ``linkage plans`` command that draws the sheets' plans and polygons
    apart at the sheets' own scales (one scale per quantity, shared by every file that draws it)."""
    scales = {**(made["kinetostatics"].scales if "kinetostatics" in made else {}),
              **(made["kinematics"].scales if "kinematics" in made else {})}
    options = [f"{option} {scales[symbol].value:g}" for option, symbol in
               (("--mu-v", "μ_v"), ("--mu-a", "μ_a"), ("--mu-f", "μ_F")) if symbol in scales]
    if not options:
        return []
    speed = f" --omega {omega:g}" if omega is not None else ""
    return [f"the plans and polygons apart at the sheets' scales: linkage plans {mech.name} --position {position}"
            f"{speed} {' '.join(options)}"]


def write_project_sheets(mech: Mechanism, out: str | Path, position: int | None = None, formats: Sequence[str] = ("pdf", "dxf"),
                         paper: str = "A1", title: TitleInfo | None = None, omega: float | None = None
                         ) -> tuple[list[Path], list[str]]:
    """Write the sheets of :func:`project_sheets` into the folder ``out`` as
    ``SCHEME_<sheet>.<format>``; returns the paths written and the notes."""
    made, notes = project_sheets(mech, position, paper, title, omega)
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for name, drawing in made:
        problems = layout_problems(drawing)
        if problems:
            notes.append(f"the {name} sheet has layout problems: " + "; ".join(problems[:5]))
        written += write(drawing, folder / f"{mech.name}_{name}", formats)
    return written, notes
