"""Course assignments from a template: draw feasible variants, solve each, write a folder per
variant with its scheme, printable sheet and answer key, and an index (``linkage variants``).

The data flow is three stages, each a function of the previous one's result:

1. :func:`select_variants` -- draws distinct variants reproducibly from a seed (or takes a
   teacher's table), checks each with :func:`linkage.kinematics.feasibility.check` and keeps the first
   ``count`` feasible ones, counting how many draws each rule rejected;
2. :func:`build_variant` -- one variant's files as bytes (scheme, given data, sheet, key, answers
   template, tables); a pure function of its arguments, so it runs the same in this process, in
   worker processes (``workers``) or on a Dask cluster (``scheduler``), and the files hold no
   path or time;
3. :func:`write_variants` -- runs 2 for every selected variant and writes the folders and the
   index (``index.csv``, ``index.pdf``, ``selection.json``).

The same template, seed and count give byte-identical keys, tables, sheets and index, whatever
the output folder, the number of workers or the scheduler.

>>> from linkage.course.template import load_template
>>> chosen = select_variants(load_template("press_slider_crank"), count=2, seed=1)
>>> [v.label for v in chosen.variants], chosen.draws >= 2
(['1', '2'], True)
"""

from __future__ import annotations

import json
import math
import re
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError, LinkageError
from ..kinematics.feasibility import RULES, Requirements, Verdict, check, parse_requirements
from ..model.scheme import SECTION_PARSERS, loads, toml_text
from ..report.results import dynamics_results, forces_results, kinematics_results
from ..report.tables import format_columns
from ..report.words import unit_for_people
from ..workers import run_all
from .overview import overview_pdf
from .given import given_data, given_json
from .grading import answers_template
from .key import answer_key
from .sheets import assignment_sheet_from_given
from .template import Template, draws, given_rows

__all__ = ["Variant", "Selection", "select_variants", "build_variant", "write_variants", "VariantFailed",
           "KEY_FIELDS", "INDEX_RESULTS", "INDEX_UNITS", "index_header"]

#: fields of an answer key besides those of ``linkage dynamics VARIANT --format json``
KEY_FIELDS = ("variant", "template", "parameters", "checks")

#: results of each variant's answer key repeated in the index (columns of ``index.csv``)
INDEX_RESULTS = ("stroke", "min_transmission_angle_deg", "driving_moment", "required_constant_inertia",
                 "flywheel_inertia", "dynamic_coefficient")

#: units of the index's results, as docs/conventions.md writes them ("" for a pure number); the
#: stroke's is the feasibility check's ``stroke_unit`` (m, or rad for a link angle)
INDEX_UNITS = {"stroke": "m", "min_transmission_angle_deg": "deg", "driving_moment": "N m",
               "required_constant_inertia": "kg m^2", "flywheel_inertia": "kg m^2", "dynamic_coefficient": ""}

#: measured figures of the feasibility check kept in an answer key's ``checks``
_CHECK_FIGURES = ("output", "stroke", "stroke_unit", "min_transmission_angle_deg", "min_transmission_angle_group",
                  "min_transmission_angle_phi_deg", "min_conditioning", "min_conditioning_group")


class VariantFailed(LinkageError):
    """A feasible variant could not be solved or drawn (the message names it)."""


@dataclass(frozen=True)
class Variant:
    """One selected variant: its ``label`` ("1", "2" ... or the teacher's), the ``free`` values
    drawn, the draw number it came from (1-based; for a teacher's table the row's line in the
    file) and the figures the feasibility check measured."""

    label: str
    free: dict[str, Any]
    draw: int
    figures: dict[str, Any] = field(default_factory=dict)

    def folder(self) -> str:
        """The variant's folder name, ``variant_K`` with K its label as it is (``variant_1`` ...
        ``variant_30``, no zero padding; a teacher's ``A1`` gives ``variant_A1``); characters other
        than letters, digits and ``_ . -`` become ``_``."""
        return "variant_" + re.sub(r"[^A-Za-z0-9_.-]+", "_", self.label)


@dataclass(frozen=True)
class Selection:
    """The result of :func:`select_variants`. For a teacher's table also ``table`` (the file's
    name), ``rows`` (its rows) and ``left_out`` (one line per infeasible row left out, naming its
    line, its values, the rule it breaks and the value measured)."""

    template: Template
    requirements: Requirements
    seed: int | None
    count: int
    variants: tuple[Variant, ...]
    draws: int
    rejected: dict[str, int]
    exhausted: bool
    reasons: dict[str, str] = field(default_factory=dict)
    table: str | None = None
    rows: int = 0
    left_out: tuple[str, ...] = ()

    def summary(self) -> dict[str, Any]:
        """How the variants were chosen (``selection.json``): the seed, the draws, the rejections
        per rule (with one example reason each) and whether the template's grid ran out; for a
        teacher's table also its name, its rows and the rows left out."""
        summary = {"template": self.template.name, "seed": self.seed, "count": self.count,
                   "found": len(self.variants), "draws": self.draws, "exhausted": self.exhausted,
                   "rejected": {rule: self.rejected.get(rule, 0) for rule in (*RULES, "invalid")},
                   "example_reasons": dict(self.reasons)}
        if self.table is not None:
            summary.update(table=self.table, rows=self.rows, left_out=list(self.left_out))
        return summary

    def lines(self) -> list[str]:
        """The selection in words, one line each (the CLI's notes and the index's notes)."""
        rejected = ", ".join(f"{rule} {n}" for rule, n in self.rejected.items() if n) or "none"
        found = f"{len(self.variants)} feasible variant" + ("" if len(self.variants) == 1 else "s")
        if self.table is not None:
            used = "" if self.draws == self.rows else f" (the first {self.draws} of its {self.rows} rows)"
            lines = [f"{found} from {self.table}{used}; "
                     f"infeasible rows left out by rule: {rejected}"]
            return lines + [f"left out: {line}" for line in self.left_out]
        lines = [f"{found} of {self.count} asked from {self.draws} draws "
                 f"(seed {self.seed}); rejected by rule: {rejected}"]
        lines += [f"e.g. {rule}: {reason}" for rule, reason in self.reasons.items()]
        if len(self.variants) < self.count:
            why = ("every combination of the template's parameters was drawn" if self.exhausted
                   else "the limit of draws was reached (--max-draws)")
            lines.append(f"only {len(self.variants)} feasible variants: {why}; widen the parameters' ranges "
                         "or relax [template.require]")
        return lines


def variant_name(template: Template, label: str) -> str:
    """The scheme name of a variant: ``<template>_<label>``."""
    return f"{template.name}_{re.sub(r'[^A-Za-z0-9_.-]+', '_', label)}"


def variant_text(template: Template, label: str, free: Mapping[str, Any]) -> str:
    """The scheme file of a variant (plain TOML, no expressions)."""
    return toml_text(template.scheme_data(free, variant_name(template, label)))


def select_variants(template: Template, count: int, seed: int | None = None, *,
                    given: str | Path | None = None, skip_infeasible: bool = False,
                    max_draws: int | None = None,
                    progress: Callable[[Iterable], Iterable] | None = None) -> Selection:
    """Draw (or take from a teacher's table) ``count`` feasible variants of ``template``.

    Parameters
    ----------
    count : int
        Variants wanted (>= 1).
    seed : int, optional
        Seed of the draws (:func:`linkage.course.template.draws`); needed without ``given``.
    given : path, optional
        A CSV of given variants (:func:`linkage.course.template.given_rows`), taken in its order
        until ``count`` are taken; its ``variant`` column labels them.
    skip_infeasible : bool
        With ``given``: leave the infeasible rows out (:attr:`Selection.left_out` says which and
        why) instead of refusing the table.
    max_draws : int, optional
        Stop after this many draws (default ``max(1000, 50 * count)``; not with ``given``).
    progress : callable, optional
        Wraps the stream of draws (a progress bar).

    Returns
    -------
    Selection
        At most ``count`` variants, labelled "1", "2" ... in the order found (or by the table's
        ``variant`` column); fewer when the grid, ``max_draws`` or the table ran out
        (:meth:`Selection.lines` says so).

    Raises
    ------
    InputError
        A given row is infeasible (without ``skip_infeasible``): one line per such row, naming
        its line in the file, its values, the rule of ``[template.require]`` it breaks and the
        value measured.
    """
    if not (isinstance(count, int) and count >= 1):
        raise InputError(f"count must be a whole number >= 1, got {count!r}")
    if given is None and seed is None:
        raise InputError("give a seed for the draws (or a table of given variants)")
    requirements = parse_requirements(template.require, f"{template.source} [template.require]")
    if given is not None:
        return _select_given(template, count, requirements, given, skip_infeasible, progress)
    limit = max_draws if max_draws is not None else max(1000, 50 * count)
    candidates = draws(template, seed)
    stream = progress(candidates) if progress is not None else candidates
    chosen: list[Variant] = []
    rejected: Counter = Counter()
    reasons: dict[str, str] = {}
    n_draws, exhausted = 0, True
    for free in stream:
        if len(chosen) == count or n_draws == limit:
            exhausted = False
            break
        n_draws += 1
        verdict = _verdict(template, free, requirements)
        if verdict.feasible:
            chosen.append(Variant(str(len(chosen) + 1), dict(free), n_draws, _figures(verdict)))
        else:
            rejected[verdict.rule] += 1
            reasons.setdefault(verdict.rule, verdict.reason)
    return Selection(template, requirements, seed, count, tuple(chosen), n_draws, dict(rejected), exhausted, reasons)


def _select_given(template: Template, count: int, requirements: Requirements, given: str | Path,
                  skip_infeasible: bool, progress) -> Selection:
    """:func:`select_variants` from a teacher's table: its rows in order until ``count`` are
    feasible; an infeasible row is an error (every one examined, at once) or, with
    ``skip_infeasible``, left out with a line saying which and why."""
    rows = given_rows(template, given)
    stream = progress(rows) if progress is not None else rows
    has_labels = _has_label_column(template, rows)
    chosen: list[Variant] = []
    rejected: Counter = Counter()
    reasons: dict[str, str] = {}
    infeasible: list[str] = []
    n_rows = 0
    for line, label, free in stream:
        if len(chosen) == count:
            break
        n_rows += 1
        verdict = _verdict(template, free, requirements)
        if verdict.feasible:
            chosen.append(Variant(label, dict(free), line, _figures(verdict)))
            continue
        rejected[verdict.rule] += 1
        reasons.setdefault(verdict.rule, verdict.reason)
        row = f"line {line} ({_row_text(label, free, has_labels)})"
        infeasible.append(f"{row} {_broken_rule(verdict, requirements)}: {verdict.reason}")
    if infeasible and not skip_infeasible:
        raise InputError("\n".join([*(f"{given}: {text}" for text in infeasible),
                                    f"{given}: correct these rows (or [template.require] of {template.name}), or "
                                    "leave the infeasible rows out with --skip-infeasible "
                                    "(Python: skip_infeasible=True)"]))
    name = Path(given).name
    return Selection(template, requirements, None, count, tuple(chosen), n_rows, dict(rejected),
                     len(chosen) < count, reasons, table=name, rows=len(rows),
                     left_out=tuple(f"{name}: {text}" for text in infeasible))


def _has_label_column(template: Template, rows) -> bool:
    """Whether a table's labels are its own (a ``variant`` column) rather than 1, 2, ... in order."""
    return any(label != str(k) for k, (_, label, _) in enumerate(rows, start=1))


def _row_text(label: str, free: Mapping[str, Any], has_labels: bool) -> str:
    """A given row in words: ``variant 'A1': crank = 0.08, ...`` (its values)."""
    return (f"variant {label!r}: " if has_labels else "") + _free_text(free)


def _broken_rule(verdict: Verdict, requirements: Requirements) -> str:
    """What an infeasible row does wrong: the rule of [template.require] it breaks, in words."""
    rule = verdict.rule
    if rule == "transmission_angle":
        return (f"breaks the rule min_transmission_angle_deg = {requirements.min_transmission_angle_deg:g} "
                "of [template.require]")
    if rule == "stroke" and requirements.stroke is not None:
        low, high = requirements.stroke
        return f"breaks the rule stroke = [{low:g}, {high:g}] of [template.require]"
    if rule in ("full_rotation", "non_singular", "no_change_point"):
        return f"breaks the rule {rule} = true of [template.require]"
    if rule == "invalid":
        return "does not make a valid scheme"
    return "does not make a mechanism that assembles"


def _figures(verdict: Verdict) -> dict[str, Any]:
    return {k: verdict.figures.get(k) for k in _CHECK_FIGURES}


def _verdict(template: Template, free: Mapping[str, Any], requirements: Requirements):
    """The feasibility verdict of one draw; a draw whose derived values or scheme are invalid is
    rejected under "invalid" with its message."""

    try:
        text = variant_text(template, "check", free)
    except LinkageError as exc:
        return Verdict(False, "invalid", str(exc).splitlines()[0], {})
    verdict = check(lambda: loads(text, source=template.source), requirements)
    if verdict.rule != "assembles" or verdict.figures:
        return verdict
    # refused while being built: its motion is judged first (a crank that cannot turn fully is
    # rejected by "full_rotation" in those words, not by the [loads] diagram that needs the turn),
    # on the mechanism alone, without the sections that read its motion ([loads], [dynamics] ...)
    data = template.scheme_data(free, variant_name(template, "check"))
    bare = {key: value for key, value in data.items() if key not in SECTION_PARSERS}
    motion = check(lambda: loads(toml_text(bare), source=template.source), requirements)
    return verdict if motion.feasible else motion


def build_variant(template: Template, variant: Variant) -> dict[str, bytes]:
    """The files of one variant, as ``{file name: bytes}``.

    ``scheme.toml`` (the variant as a plain scheme); ``given.json`` (what the student is given,
    machine-readable: every datum the answer key depends on, the whole scheme among them,
    :func:`linkage.course.given.given_data`); ``sheet.pdf`` (the printable assignment, rendered
    from ``given.json`` alone: :func:`linkage.course.sheets.assignment_sheet_from_given`);
    ``key.json`` and ``key.csv`` (the answer key for grading step by step,
    :func:`linkage.course.key.answer_key`: ``key.json`` holds every field of ``linkage dynamics
    scheme.toml --format json`` with the same values, plus ``variant``, ``template``,
    ``parameters`` (every parameter's value), ``checks`` (what the feasibility check measured) and
    the items); ``answers.csv`` (the file a student fills in: ``key.csv``'s quantities and
    positions with empty values, :func:`linkage.course.grading.answers_template`);
    ``kinematics.csv``, ``forces.csv`` and ``dynamics.csv`` (the tables of ``linkage analyze``,
    ``linkage forces`` and ``linkage dynamics`` in CSV). Nothing in them depends on the time or
    on where they are written.

    Raises
    ------
    VariantFailed
        The variant cannot be solved or drawn (naming the variant and the cause).
    """

    try:
        text = variant_text(template, variant.label, variant.free)
        mech = loads(text, source=f"variant {variant.label}")
        dynamics = dynamics_results(mech)
        kinematics = kinematics_results(mech)
        forces = forces_results(mech)
        values = template.values(variant.free)
        given = json.loads(given_json(given_data(template, variant, values, mech, text)))
        sheet = assignment_sheet_from_given(given)
        key = answer_key(mech, template.grading, variant=variant.label, template=template, parameters=values,
                         checks=variant.figures, dynamics=dynamics)
        key_csv = key.to_csv()
        answers = answers_template(key_csv, variant.folder())
    except LinkageError as exc:
        raise VariantFailed(f"variant {variant.label} ({_free_text(variant.free)}): {exc}") from None
    return {
        "scheme.toml": text.encode(),
        "given.json": given_json(given).encode(),
        "key.json": key.to_json().encode(),
        "key.csv": key_csv.encode(),
        "answers.csv": answers.encode(),
        "kinematics.csv": format_columns(kinematics.columns, "csv").encode(),
        "forces.csv": format_columns(forces.columns, "csv").encode(),
        "dynamics.csv": format_columns(dynamics.columns, "csv").encode(),
        "sheet.pdf": sheet,
    }


def _value_text(value: Any) -> str:
    return f"{value:.10g}" if isinstance(value, float) else str(value)


def _free_text(free: Mapping[str, Any]) -> str:
    return ", ".join(f"{k} = {_value_text(v)}" for k, v in free.items())


def write_variants(selection: Selection, out: str | Path, *, workers: int = 1, scheduler: str | None = None,
                   progress: Callable[[Iterable, int], Iterable] | None = None) -> list[Path]:
    """Build every selected variant and write the folders and the index into ``out``.

    Parameters
    ----------
    selection : Selection
        From :func:`select_variants`.
    out : path
        The output folder (created; files of the same names are replaced).
    workers : int
        Worker processes (1: in this process).
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tcp://host:8786``) to build the variants on
        instead of local processes.
    progress : callable, optional
        ``progress(iterable, total)`` wraps the stream of built variants (a progress bar).

    Returns
    -------
    list of Path
        The variant folders, in order.
    """

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: is a file, not a folder")
    if not (isinstance(workers, int) and workers >= 1):
        raise InputError(f"workers must be a whole number >= 1, got {workers!r}")
    variants = list(selection.variants)
    template, seed = selection.template, selection.seed
    built = zip(variants, run_all(build_variant, [(template, v) for v in variants], workers=workers,
                                  scheduler=scheduler), strict=True)
    if progress is not None:
        built = progress(built, len(variants))
    out.mkdir(parents=True, exist_ok=True)
    folders, rows = [], []
    for variant, files in built:
        folder = out / variant.folder()
        folder.mkdir(exist_ok=True)
        for name, content in files.items():
            (folder / name).write_bytes(content)
        folders.append(folder)
        rows.append(_index_row(template, variant, folder.name, json.loads(files["key.json"])))
    stroke_unit = next((v.figures.get("stroke_unit") for v in variants if v.figures.get("stroke_unit")), "m")
    columns = index_header(template, stroke_unit)
    header = [f"{name} [{unit}]" if unit else name for name, unit in columns]
    (out / "index.csv").write_bytes(_csv(header, rows).encode())
    (out / "selection.json").write_bytes((json.dumps(selection.summary(), indent=1) + "\n").encode())
    # the printed index: no folder column (it is variant_<label>), the results to 4 significant digits
    shown = [k for k, (name, _) in enumerate(columns) if name != "folder"]
    first_result = len(columns) - len(INDEX_RESULTS)
    source = f" (seed {seed})" if seed is not None else f" ({selection.table})" if selection.table else ""
    (out / "index.pdf").write_bytes(overview_pdf(
        title=f"{template.name}: {len(rows)} variants{source}", header=[columns[k][0] for k in shown],
        units=[_unit_for_people(*columns[k]) for k in shown],
        rows=[[_cell(row[k], 4 if k >= first_result else 6) for k in shown] for row in rows],
        notes=selection.lines()))
    return folders


def index_header(template: Template, stroke_unit: str = "m") -> list[tuple[str, str]]:
    """The columns of the index, ``[(name, unit), ...]``: ``variant``, ``folder``, the free
    parameters (their units as the template declares them) and :data:`INDEX_RESULTS` (units
    :data:`INDEX_UNITS`; the stroke's is ``stroke_unit``); ``""`` for no unit. ``index.csv``
    names a column with a unit ``name [unit]`` (``crank [m]``, ``driving_moment [N m]``), units as
    docs/conventions.md writes them (ASCII); ``index.pdf`` prints the unit under the name, with
    real symbols (kg·m²)."""
    units = {**INDEX_UNITS, "stroke": stroke_unit}
    return [("variant", ""), ("folder", ""), *((n, template.parameter(n).unit) for n in template.free),
            *((k, units[k]) for k in INDEX_RESULTS)]


def _unit_for_people(name: str, unit: str) -> str:
    """The unit under a column's name in ``index.pdf``: ``[kg·m²]``, ``—`` for a pure number,
    nothing under the variant's label."""
    if name in ("variant", "folder"):
        return ""
    return f"[{unit_for_people(unit)}]" if unit else "—"


def _index_row(template: Template, variant: Variant, folder: str, key: Mapping[str, Any]) -> list:
    found = {**key.get("checks", {}), **key}
    return [variant.label, folder, *(variant.free[n] for n in template.free), *(found.get(k) for k in INDEX_RESULTS)]


def _cell(x: Any, digits: int = 6) -> str:
    """A value of the printed index: a number to ``digits`` significant digits (whole, not in
    powers of ten, from 10**digits up), None as an empty cell."""
    if x is None:
        return ""
    if isinstance(x, float):
        text = f"{x:.{digits}g}"
        return f"{x:.0f}" if "e+" in text else text
    return str(x)


def _csv(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    import csv
    import io

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow(["" if x is None else repr(x) if isinstance(x, float) and math.isfinite(x) else x
                         for x in row])
    return buffer.getvalue()
