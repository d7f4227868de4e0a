"""Enumerate pair kinds: every R/P assignment of a chain's pairs, each as a scheme that runs a full turn.

:func:`enumerate_chain` takes every assignment of a scheme's chain
(:func:`~.assignments.assignments`), lists those that are not solvable with the reason
(:class:`Rejected`, :func:`~.geometry.solvable`) and measures the others (:func:`measure`
measures one). Each gets the source's geometry at a reference position (:mod:`~.geometry`; a
group solved by Newton's method its mode there, :mod:`~.placement`) and is loaded as a scheme,
which is checked to run a full turn: assembled, regular, no change point and not close to a
singular position, and for a group solved by Newton's method in the mode of the reference
position. A combination whose geometry does not run a full turn (or comes close to a singular
position) is tried with a shorter crank (:data:`CRANK_FACTORS`) and other reference positions;
where none runs, it is listed with the reason and never written. One that runs is measured
(:class:`Combination`: its output's stroke, smallest transmission angle, peak balancing moment);
:class:`Enumeration` holds the table and writes the schemes.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from assur.base import OK

from ..errors import AssemblyError, InputError, LinkageError, SchemeError, StructureError
from ..kinematics.extremes import extreme_positions
from ..kinematics.feasibility import check, sweep_angles
from ..kinematics.motion import BranchWarning, analyze
from ..kinetostatics.reactions import solve_reactions
from ..model.mechanism import Mechanism
from ..model.scheme import dumps, load, loads
from ..report import format_columns
from ..structure import Structure
from .assignments import Assignment, Reference, assignments, reference_positions
from .geometry import one_line, output_candidates, solvable
from .placement import (
    CONDITION_TRIALS,
    MIN_CONDITIONING,
    Placement,
    declared_combination,
    placement,
    singular_words,
    too_close_to_singular,
    tracked_groups,
)

__all__ = [
    "COLUMN_UNITS",
    "CRANK_FACTORS",
    "DEFAULT_OMEGA",
    "POSITIONS",
    "Combination",
    "Enumeration",
    "Rejected",
    "enumerate_chain",
    "measure",
]

#: lengths of the crank tried, as fractions of the source's crank, until a combination runs a full turn
CRANK_FACTORS = (1.0, 0.8, 0.6, 0.4, 0.2)
#: input speed of the balancing moment in the table, rad/s (counter-clockwise)
DEFAULT_OMEGA = 10.0
#: input angles of a turn checked and measured (1 deg steps)
POSITIONS = 360


# ----------------------------------------------------------------------------------------------
# measuring a combination
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Combination:
    """One valid assignment: its structure and, where a geometry runs a full turn, its figures.

    Attributes
    ----------
    assignment : Assignment
    formula : str
        Structural formula, e.g. ``I(0,1) → II-RPR(2,3)``.
    full_turn : bool or None
        A geometry was found that assembles, stays regular and passes no change point over a turn;
        None: not searched (a combination solved by Newton's method, without ``newton=True``).
    crank_factor : float or None
        The crank's length as a fraction of the source's in that geometry.
    reference_deg : float or None
        The input angle of the source's reference position it was taken at, deg.
    output : str
        The measured quantity (``"B.x"``, ``"3.theta"``, ``"K.s"``).
    stroke : float or None
        Its stroke over a turn: m for a point coordinate or a slide, deg for a link angle (the
        swing); None without a full turn or when no candidate output has one.
    stroke_unit : str
        ``"m"`` or ``"deg"``.
    min_transmission_angle_deg : float or None
        Smallest transmission angle over the turn, deg; None when no group has one.
    peak_balancing_moment : float or None
        ``max |M_b|`` over the turn at the enumeration's speed, N m.
    note : str
        Why no geometry was found, or what the figures leave out.
    scheme : str or None
        The TOML text of the combination's scheme (full turn only).
    """

    assignment: Assignment
    formula: str
    full_turn: bool | None
    crank_factor: float | None
    reference_deg: float | None
    output: str
    stroke: float | None
    stroke_unit: str
    min_transmission_angle_deg: float | None
    peak_balancing_moment: float | None
    note: str
    scheme: str | None

    @property
    def id(self) -> str:
        return self.assignment.id


@dataclass(frozen=True)
class Rejected:
    """An assignment that is not solvable, and why: it does not decompose into groups a registered
    solver binds, or a group's prismatic pairs close a loop (:func:`~.geometry.solvable`)."""

    assignment: Assignment
    reason: str

    @property
    def id(self) -> str:
        return self.assignment.id


def _scheme_text(mech: Mechanism, source: Mechanism, assignment: Assignment, ref: Reference) -> str:
    """The scheme file of a combination: comments saying where it comes from, then the scheme."""
    header = [f"# {assignment.id}: scheme '{source.name}' with pairs " + ", ".join(k.words for k in assignment.kinds),
              (f"# written by `linkage enumerate {source.name}`: geometry of the source at phi = "
               f"{math.degrees(ref.phi):.6g} deg (docs/enumerate.md); each group keeps the assembly "
               "branch or mode of that position")]
    return "\n".join(header) + "\n" + dumps(mech)


def _full_turn_problem(mech: Mechanism) -> tuple[str | None, dict]:
    """Why ``mech`` does not run a full turn (:func:`linkage.kinematics.feasibility.check`: it assembles at
    every angle of a 1 deg sweep, stays regular, passes no change point) or comes close to a
    singular position (:func:`~.placement.too_close_to_singular` on every group's conditioning),
    or None; and the check's figures."""
    verdict = check(mech)
    if not verdict.feasible:
        return verdict.reason, verdict.figures
    if verdict.figures["min_conditioning"] >= MIN_CONDITIONING:
        return None, verdict.figures
    motion = analyze(mech, sweep_angles(mech, POSITIONS), order=0, on_failure="mask")
    for group in motion.structure.groups:
        ratios = motion.conditioning[repr(group)]
        if too_close_to_singular(group, ratios):
            largest = None if len(group.links) == 2 else float(np.nanmax(ratios))
            return singular_words(group, float(np.nanmin(ratios)), None, largest), verdict.figures
    return None, verdict.figures


def _stroke_of(mech: Mechanism, candidates: list[str]) -> tuple[str, float | None, str]:
    """The first candidate with a stroke (between its extreme positions, :func:`linkage.extreme_positions`):
    ``(quantity, stroke in m or deg, note)``; the first candidate, None and why when none has one."""
    for quantity in candidates:
        try:
            ext = extreme_positions(mech, quantity)
        except LinkageError:  # constant, or monotonic: a link that turns fully
            continue
        if ext.moves(mech.size):
            stroke = ext.stroke
            return quantity, math.degrees(stroke) if quantity.endswith(".theta") else stroke, ""
    return candidates[0], None, f"no stroke: {', '.join(candidates)} stay constant or turn fully"


def _peak_balancing_moment(mech: Mechanism, omega: float) -> float:
    """``max |M_b|`` over a turn (:data:`POSITIONS` angles) at the constant speed ``omega``, N m."""
    phi = np.linspace(0.0, 2 * np.pi, POSITIONS, endpoint=False)
    motion = analyze(mech, phi, omega=omega, eps=0.0)
    return float(np.max(np.abs(solve_reactions(motion).balancing_moment)))


def _measured(source: Mechanism, assignment: Assignment, structure: Structure, ref: Reference, omega: float,
              factor: float, candidates: list[str]) -> Combination | str:
    """The combination with the crank ``factor`` and the geometry of ``ref``, measured; or the
    reason it does not run a full turn."""
    try:
        place = placement(source, ref, assignment, factor) if tracked_groups(structure) else None
        if place is not None and place.problem is not None:
            return place.problem
        mech, choice, text = _loaded(source, assignment, factor, ref, candidates[0], structure, place)
        problem, figures = _full_turn_problem(mech)
        if problem is not None:
            return problem
        output, stroke, note = _stroke_of(mech, candidates)
        if output != candidates[0]:
            text = _scheme_text(declared_combination(source, assignment, factor, ref, output, choice, structure,
                                                     place), source, assignment, ref)
            mech = loads(text, source=assignment.file_name)
        peak = _peak_balancing_moment(mech, omega)
    except LinkageError as exc:
        return one_line(exc)
    return Combination(assignment, structure.formula, True, factor, math.degrees(ref.phi), output, stroke,
                       _unit(output), figures.get("min_transmission_angle_deg"), peak, note, text)


def _loaded(source: Mechanism, assignment: Assignment, factor: float, ref: Reference, output: str,
            structure: Structure, place: Placement | None) -> tuple[Mechanism, int, str]:
    """The combination's scheme loaded, the choice of conditions (:func:`~.placement.build_combination`) it
    has, and its text.

    With groups solved by Newton's method (``place`` given) the conditions of
    :func:`~.placement.mode_conditions` are tried in turn until the scheme loads and its traced mode at the
    reference angle is the mode of ``place`` (to 1e-8 of the size).

    Raises
    ------
    AssemblyError
        When no condition tried does (naming the angle and why each failed).
    """
    def loaded(choice: int) -> tuple[Mechanism, int, str]:
        text = _scheme_text(declared_combination(source, assignment, factor, ref, output, choice, structure, place),
                            source, assignment, ref)
        return loads(text, source=assignment.file_name), choice, text

    if place is None:
        return loaded(0)
    reasons = []
    for choice in range(CONDITION_TRIALS):
        try:
            found = loaded(choice)
        except AssemblyError as exc:       # no further condition
            reasons.append(one_line(exc))
            break
        except SchemeError as exc:
            reasons.append(one_line(exc))
            if "assembly of point" in str(exc):     # the condition does not tell the modes apart: try the next
                continue
            break
        mech = found[0]
        motion = analyze(mech, [ref.phi], order=0, on_failure="mask")
        miss = place.mismatch({k: motion.poses[k][0] for group in structure.groups for k in group.links})
        if motion.status[0] == OK and miss <= 1e-8 * mech.size:
            return found
        reasons.append(f"with {_condition_words(mech)} the traced mode at the reference angle is not the reference "
                       f"position's ({miss:.3g} m apart)")
    raise AssemblyError(f"no readable assembly condition picks the mode of the reference position at phi = "
                        f"{math.degrees(ref.phi):.6g} deg: " + "; ".join(reasons), np.array([math.degrees(ref.phi)]))


def _condition_words(mech: Mechanism) -> str:
    """The readable assembly conditions of ``mech``: ``"D left_of [F, C]"``."""
    return ", ".join(f"{a.point} {a.rule} [{', '.join(a.refs)}]" for a in mech.assembly if a.rule != "branch")


def _unit(quantity: str) -> str:
    """The unit of a stroke of ``quantity`` in the table: deg for a link's angle, else m."""
    return "deg" if quantity.endswith(".theta") else "m"


def _combination(source: Mechanism, assignment: Assignment, structure: Structure, refs: list[Reference],
                 omega: float, factors: tuple[float, ...]) -> Combination:
    """The first geometry that runs a full turn: each crank factor in turn, at each reference
    position; else the combination without figures, with the reason found at the first."""
    candidates = output_candidates(source, assignment, structure)
    reasons = []
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", BranchWarning)
        for factor in factors:
            for ref in refs:
                found = _measured(source, assignment, structure, ref, omega, factor, candidates)
                if isinstance(found, Combination):
                    return found
                reasons.append(found)
    if not reasons:
        note = "geometry not searched"
    else:
        note = (f"no full-turn geometry found: {reasons[0]} (nor at the other {len(reasons) - 1} trials: crank "
                f"{', '.join(f'{f:g}' for f in factors)} of the source's, each at {len(refs)} reference positions)")
    return Combination(assignment, structure.formula, False, None, None, candidates[0], None, _unit(candidates[0]),
                       None, None, note, None)


# ----------------------------------------------------------------------------------------------
# the enumeration
# ----------------------------------------------------------------------------------------------

#: columns of the table and their units (None: text or a pure number)
COLUMN_UNITS = {"id": None, "formula": None, "full_turn": None, "crank_factor": None, "reference_deg": "deg",
                "output": None, "stroke": "m or deg", "stroke_unit": None, "min_transmission_angle_deg": "deg",
                "peak_balancing_moment": "N m", "note": None}


@dataclass(frozen=True)
class Enumeration:
    """Every assignment of a chain: the valid ones measured, the others with the reason.

    Attributes
    ----------
    source : str
        The source scheme's name.
    omega : float
        Input speed of the balancing moment, rad/s.
    references_deg : tuple of float
        Input angles of the source's reference positions, in the order tried, deg.
    combinations : tuple of Combination
        The valid assignments, in the order of :func:`~.assignments.assignments`.
    rejected : tuple of Rejected
        The others.
    """

    source: str
    omega: float
    references_deg: tuple[float, ...]
    combinations: tuple[Combination, ...]
    rejected: tuple[Rejected, ...]

    def columns(self) -> dict[str, np.ndarray]:
        """The table: one row per valid assignment, the columns of :data:`COLUMN_UNITS`.

        ``id``; ``formula``; ``full_turn`` (``yes`` / ``no`` / ``not searched``); ``crank_factor`` (the crank as a
        fraction of the source's); ``reference_deg`` (the source's position the geometry is taken
        at, deg); ``output``; ``stroke`` (in ``stroke_unit``: m, or deg for a link's swing);
        ``min_transmission_angle_deg`` (deg); ``peak_balancing_moment`` (N m, the largest
        ``|M_b|`` over a turn at ``omega``); ``note``. Missing numbers are NaN.
        """
        rows = self.combinations

        def numbers(name: str) -> np.ndarray:
            values = [getattr(c, name) for c in rows]
            return np.array([np.nan if v is None else float(v) for v in values], dtype=float)

        def texts(values) -> np.ndarray:
            return np.array(list(values), dtype=object)

        return {
            "id": texts(c.id for c in rows),
            "formula": texts(c.formula for c in rows),
            "full_turn": texts("not searched" if c.full_turn is None else "yes" if c.full_turn else "no"
                               for c in rows),
            "crank_factor": numbers("crank_factor"),
            "reference_deg": numbers("reference_deg"),
            "output": texts(c.output for c in rows),
            "stroke": numbers("stroke"),
            "stroke_unit": texts(c.stroke_unit for c in rows),
            "min_transmission_angle_deg": numbers("min_transmission_angle_deg"),
            "peak_balancing_moment": numbers("peak_balancing_moment"),
            "note": texts(c.note for c in rows),
        }

    def rejected_columns(self) -> dict[str, np.ndarray]:
        """The rejected assignments: ``id`` and ``reason``."""
        return {"id": np.array([r.id for r in self.rejected], dtype=object),
                "reason": np.array([r.reason for r in self.rejected], dtype=object)}

    def write(self, folder: str | Path) -> list[Path]:
        """Write ``<id>.toml`` for every combination that runs a full turn, ``combinations.csv``
        (the table) and ``rejected.csv`` into ``folder`` (created); return the files written.

        Raises
        ------
        InputError
            When the folder cannot be created or written (naming it).
        """
        folder = Path(folder)
        files = {c.assignment.file_name: c.scheme for c in self.combinations if c.scheme is not None}
        files["combinations.csv"] = _csv(self.columns())
        files["rejected.csv"] = _csv(self.rejected_columns())
        try:
            folder.mkdir(parents=True, exist_ok=True)
            for name, text in files.items():
                (folder / name).write_text(text, encoding="utf-8")
        except OSError as exc:
            raise InputError(f"{folder}: cannot be written ({exc.strerror or exc})") from None
        return [folder / name for name in files]


def _csv(columns: dict[str, np.ndarray]) -> str:
    """CSV text of a table (the header alone when it has no rows)."""
    return format_columns(columns, "csv") if len(next(iter(columns.values()))) else ",".join(columns) + "\n"


def enumerate_chain(source: Mechanism | str | Path, *, omega: float = DEFAULT_OMEGA,
                    factors: Iterable[float] = CRANK_FACTORS, geometry: bool = True, newton: bool = False,
                    progress: Callable | None = None) -> Enumeration:
    """Enumerate the pair kinds of a scheme's chain and measure every valid combination.

    Parameters
    ----------
    source : Mechanism, str or Path
        A mechanism, a shipped scheme name or a scheme file (one input link).
    omega : float
        Input speed for the balancing moment, rad/s (finite, nonzero).
    factors : iterable of float
        Crank lengths tried, as fractions of the source's, until a geometry runs a full turn (each
        at every reference position of :func:`~.assignments.reference_positions`).
    geometry : bool
        False: only decompose (no geometry search; every combination is listed without figures).
    newton : bool
        Search the geometry of the combinations with a group solved by Newton's method too (each
        written scheme traces its modes when loaded: about 1-2 s per trial, minutes for a
        six-bar); default False: they are listed with ``full_turn`` None ("not searched").
    progress : callable, optional
        ``progress(iterable, total)`` wrapping the loop over the valid assignments (a tqdm bar).

    Returns
    -------
    Enumeration
    """
    mech = _source(source)
    omega, factors = _checked(omega, factors)
    refs = reference_positions(mech)
    valid, rejected = [], []
    for assignment in assignments(mech):
        found = solvable(mech, refs[0], assignment)
        if isinstance(found, str):
            rejected.append(Rejected(assignment, found))
        else:
            valid.append((assignment, found))
    loop = valid if progress is None else progress(valid, len(valid))
    rows = [_combination(mech, assignment, structure, refs, omega, factors if geometry else ())
            if newton or not geometry or not tracked_groups(structure) else _unsearched(mech, assignment, structure)
            for assignment, structure in loop]
    return Enumeration(mech.name, omega, tuple(math.degrees(r.phi) for r in refs), tuple(rows), tuple(rejected))


def _unsearched(source: Mechanism, assignment: Assignment, structure: Structure) -> Combination:
    """A combination with a group solved by Newton's method, listed without a geometry search."""
    output = output_candidates(source, assignment, structure)[0]
    return Combination(assignment, structure.formula, None, None, None, output, None, _unit(output), None, None,
                       "a group's modes are traced over the turn (the triad, or Newton's method): geometry not "
                       "searched (--newton searches it, slowly)",
                       None)


def measure(source: Mechanism | str | Path, assignment: Assignment | str, *, omega: float = DEFAULT_OMEGA,
            factors: Iterable[float] = CRANK_FACTORS) -> Combination:
    """One assignment's combination, measured as :func:`enumerate_chain` measures each.

    Parameters
    ----------
    source : Mechanism, str or Path
        A mechanism, a shipped scheme name or a scheme file (one input link).
    assignment : Assignment or str
        One of :func:`~.assignments.assignments`, or its id (``"A=R,B=P3,C=R"``).
    omega, factors
        As for :func:`enumerate_chain`.

    Returns
    -------
    Combination

    Raises
    ------
    InputError
        For an id that is no assignment of the chain (naming it).
    StructureError
        When the assignment is not solvable (the reason :class:`Rejected` would give).
    """
    mech = _source(source)
    omega, factors = _checked(omega, factors)
    if isinstance(assignment, str):
        known = {a.id: a for a in assignments(mech)}
        if assignment not in known:
            raise InputError(f"scheme '{mech.name}': {assignment!r} is no assignment of its pairs "
                             f"(e.g. {next(iter(known))!r})")
        assignment = known[assignment]
    refs = reference_positions(mech)
    found = solvable(mech, refs[0], assignment)
    if isinstance(found, str):
        raise StructureError(f"scheme '{mech.name}', assignment {assignment.id}: {found}")
    return _combination(mech, assignment, found, refs, omega, factors)


def _source(source: Mechanism | str | Path) -> Mechanism:
    return source if isinstance(source, Mechanism) else load(source)


def _checked(omega: float, factors: Iterable[float]) -> tuple[float, tuple[float, ...]]:
    """``omega`` and the crank factors, checked (:class:`InputError` naming a bad value)."""
    if not (math.isfinite(omega) and omega != 0.0):
        raise InputError(f"omega must be a finite nonzero speed in rad/s, got {omega!r}")
    factors = tuple(float(f) for f in factors)
    if not all(0.0 < f <= 1.0 for f in factors):
        raise InputError(f"crank factors must be fractions in (0, 1], got {list(factors)}")
    return float(omega), factors
