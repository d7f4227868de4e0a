"""Course assignments from a template: draw feasible variants, solve each, write a folder per
variant with its scheme, printable sheet and answer key, and an index (``linkage variants``).

The data flow is three stages, each a function of the previous one's result:

1. :func:`select_variants` -- draws distinct variants reproducibly from a seed (or takes a
   teacher's table), checks each with :func:`linkage.kinematics.feasibility.check` and keeps the first
   ``count`` feasible ones, counting how many draws each rule rejected;
2. :func:`build_variant` -- one variant's files as bytes (scheme, key, tables, sheet); a pure
   function of its arguments, so it runs the same in this process, in worker processes
   (``workers``) or on a Dask cluster (``scheduler``), and the files hold no path or time;
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
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError, LinkageError
from ..kinematics.feasibility import RULES, Requirements, Verdict, check, parse_requirements
from ..model.scheme import loads, toml_text
from ..report.results import dynamics_results, forces_results, kinematics_results
from ..report.tables import format_columns
from .overview import overview_pdf
from .sheets import assignment_sheet
from .template import Template, draws, given_variants

__all__ = ["Variant", "Selection", "select_variants", "build_variant", "write_variants", "VariantFailed",
           "KEY_FIELDS", "INDEX_RESULTS"]

#: fields of an answer key besides those of ``linkage dynamics VARIANT --format json``
KEY_FIELDS = ("variant", "template", "parameters", "checks")

#: results of each variant's answer key repeated in the index (columns of ``index.csv``)
INDEX_RESULTS = ("stroke", "min_transmission_angle_deg", "driving_moment", "required_constant_inertia",
                 "flywheel_inertia", "dynamic_coefficient")

#: measured figures of the feasibility check kept in an answer key's ``checks``
_CHECK_FIGURES = ("output", "stroke", "stroke_unit", "min_transmission_angle_deg", "min_transmission_angle_group",
                  "min_transmission_angle_phi_deg", "min_conditioning", "min_conditioning_group")


class VariantFailed(LinkageError):
    """A feasible variant could not be solved or drawn (the message names it)."""


@dataclass(frozen=True)
class Variant:
    """One selected variant: its ``label`` ("1", "2" ... or the teacher's), the ``free`` values
    drawn, the draw number it came from (1-based; the row for a teacher's table) and the figures
    the feasibility check measured."""

    label: str
    free: dict[str, Any]
    draw: int
    figures: dict[str, Any] = field(default_factory=dict)

    def folder(self, width: int = 1) -> str:
        """The variant's folder name: ``variant_01`` ... (numbers zero-padded to ``width``)."""
        label = self.label.zfill(width) if self.label.isdigit() else self.label
        return "variant_" + re.sub(r"[^A-Za-z0-9_.-]+", "_", label)


@dataclass(frozen=True)
class Selection:
    """The result of :func:`select_variants`."""

    template: Template
    requirements: Requirements
    seed: int | None
    count: int
    variants: tuple[Variant, ...]
    draws: int
    rejected: dict[str, int]
    exhausted: bool
    reasons: dict[str, str] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """How the variants were chosen (``selection.json``): the seed, the draws, the rejections
        per rule (with one example reason each) and whether the template's grid ran out."""
        return {"template": self.template.name, "seed": self.seed, "count": self.count,
                "found": len(self.variants), "draws": self.draws, "exhausted": self.exhausted,
                "rejected": {rule: self.rejected.get(rule, 0) for rule in (*RULES, "invalid")},
                "example_reasons": dict(self.reasons)}

    def lines(self) -> list[str]:
        """The selection in words, one line each (the CLI's notes and the index's notes)."""
        rejected = ", ".join(f"{rule} {n}" for rule, n in self.rejected.items() if n) or "none"
        source = f"seed {self.seed}" if self.seed is not None else "the given table"
        lines = [f"{len(self.variants)} feasible variants of {self.count} asked from {self.draws} draws "
                 f"({source}); rejected by rule: {rejected}"]
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
                    given: str | Path | None = None, max_draws: int | None = None,
                    progress: Callable[[Iterable], Iterable] | None = None) -> Selection:
    """Draw (or take from a teacher's table) ``count`` feasible variants of ``template``.

    Parameters
    ----------
    count : int
        Variants wanted (>= 1).
    seed : int, optional
        Seed of the draws (:func:`linkage.course.template.draws`); needed without ``given``.
    given : path, optional
        A CSV of given variants (:func:`linkage.course.template.given_variants`), taken in its order;
        its ``variant`` column labels them.
    max_draws : int, optional
        Stop after this many draws (default ``max(1000, 50 * count)``).
    progress : callable, optional
        Wraps the stream of draws (a progress bar).

    Returns
    -------
    Selection
        At most ``count`` variants, labelled "1", "2" ... in the order found; fewer when the grid
        or ``max_draws`` ran out (:meth:`Selection.lines` says so).
    """
    if not (isinstance(count, int) and count >= 1):
        raise InputError(f"count must be a whole number >= 1, got {count!r}")
    if given is None and seed is None:
        raise InputError("give a seed for the draws (or a table of given variants)")
    requirements = parse_requirements(template.require, f"{template.source} [template.require]")
    limit = max_draws if max_draws is not None else max(1000, 50 * count)
    candidates: Iterator[tuple[str | None, dict]]
    if given is not None:
        candidates = iter(given_variants(template, given))
    else:
        candidates = ((None, free) for free in draws(template, seed))
    stream = progress(candidates) if progress is not None else candidates
    chosen: list[Variant] = []
    rejected: Counter = Counter()
    reasons: dict[str, str] = {}
    n_draws, exhausted = 0, True
    for label, free in stream:
        if len(chosen) == count or n_draws == limit:
            exhausted = False
            break
        n_draws += 1
        verdict = _verdict(template, free, requirements)
        if verdict.feasible:
            chosen.append(Variant(label or str(len(chosen) + 1), dict(free), n_draws,
                                  {k: verdict.figures.get(k) for k in _CHECK_FIGURES}))
        else:
            rejected[verdict.rule] += 1
            reasons.setdefault(verdict.rule, verdict.reason)
    if given is not None:
        exhausted = len(chosen) < count
    return Selection(template, requirements, seed, count, tuple(chosen), n_draws, dict(rejected), exhausted, reasons)


def _verdict(template: Template, free: Mapping[str, Any], requirements: Requirements):
    """The feasibility verdict of one draw; a draw whose derived values or scheme are invalid is
    rejected under "invalid" with its message."""

    try:
        text = variant_text(template, "check", free)
    except LinkageError as exc:
        return Verdict(False, "invalid", str(exc).splitlines()[0], {})
    return check(lambda: loads(text, source=template.source), requirements)


def build_variant(template: Template, variant: Variant) -> dict[str, bytes]:
    """The files of one variant, as ``{file name: bytes}``.

    ``scheme.toml`` (the variant as a plain scheme), ``key.json`` (the answer key: every field of
    ``linkage dynamics scheme.toml --format json`` with the same values, plus ``variant``,
    ``template``, ``parameters`` (every parameter's value) and ``checks`` (what the feasibility
    check measured)), ``kinematics.csv``, ``forces.csv`` and ``dynamics.csv`` (the tables of
    ``linkage analyze``, ``linkage forces`` and ``linkage dynamics`` in CSV) and ``sheet.pdf``
    (the printable assignment). Nothing in them depends on the time or on where they are
    written.

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
        key = {"variant": variant.label, "template": template.name, "parameters": values,
               "checks": variant.figures, **json.loads(dynamics.json())}
        sheet = assignment_sheet(mech, title=f"Assignment {variant.label} — {template.name}",
                                 subtitle=template.description, data=sheet_data(template, values),
                                 tasks=template.tasks)
    except LinkageError as exc:
        raise VariantFailed(f"variant {variant.label} ({_free_text(variant.free)}): {exc}") from None
    return {
        "scheme.toml": text.encode(),
        "key.json": (json.dumps(key, ensure_ascii=False, indent=1, allow_nan=False) + "\n").encode(),
        "kinematics.csv": format_columns(kinematics.columns, "csv").encode(),
        "forces.csv": format_columns(forces.columns, "csv").encode(),
        "dynamics.csv": format_columns(dynamics.columns, "csv").encode(),
        "sheet.pdf": sheet,
    }


def sheet_data(template: Template, values: Mapping[str, Any]) -> list[tuple[str, str, str]]:
    """The data table of a sheet: (label, value, unit) of every parameter with a label, in
    declaration order (a parameter without a label is a helper of the template's and is left
    out)."""
    return [(p.label, _value_text(values[p.name]), p.unit) for p in template.parameters if p.label]


def _value_text(value: Any) -> str:
    return f"{value:.10g}" if isinstance(value, float) else str(value)


def _free_text(free: Mapping[str, Any]) -> str:
    return ", ".join(f"{k} = {_value_text(v)}" for k, v in free.items())


def _run_serial(template, variants):
    for v in variants:
        yield v, build_variant(template, v)


def _run_processes(template, variants, workers: int):
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(build_variant, template, v) for v in variants]
        for v, future in zip(variants, futures, strict=True):
            yield v, future.result()


def _run_dask(template, variants, scheduler: str):
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler needs Dask's distributed scheduler: pip install 'linkage[dask]'") from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise InputError(f"--scheduler {scheduler}: cannot reach a Dask scheduler there ({exc})") from None
    with client:
        futures = [client.submit(build_variant, template, v, pure=False) for v in variants]
        for v, future in zip(variants, futures, strict=True):
            yield v, future.result()


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
    if scheduler is not None:
        built = _run_dask(template, variants, scheduler)
    elif workers > 1 and len(variants) > 1:
        built = _run_processes(template, variants, workers)
    else:
        built = _run_serial(template, variants)
    if progress is not None:
        built = progress(built, len(variants))
    out.mkdir(parents=True, exist_ok=True)
    width = len(str(len(variants)))
    folders, rows = [], []
    for variant, files in built:
        folder = out / variant.folder(width)
        folder.mkdir(exist_ok=True)
        for name, content in files.items():
            (folder / name).write_bytes(content)
        folders.append(folder)
        rows.append(_index_row(template, variant, folder.name, json.loads(files["key.json"])))
    header = ["variant", "folder", *template.free, *INDEX_RESULTS]
    (out / "index.csv").write_bytes(_csv(header, rows).encode())
    (out / "selection.json").write_bytes((json.dumps(selection.summary(), indent=1) + "\n").encode())
    (out / "index.pdf").write_bytes(overview_pdf(
        title=f"{template.name}: {len(rows)} variants" + (f" (seed {seed})" if seed is not None else ""),
        header=header, rows=[[_cell(x) for x in row] for row in rows], notes=selection.lines()))
    return folders


def _index_row(template: Template, variant: Variant, folder: str, key: Mapping[str, Any]) -> list:
    found = {**key.get("checks", {}), **key}
    return [variant.label, folder, *(variant.free[n] for n in template.free), *(found.get(k) for k in INDEX_RESULTS)]


def _cell(x: Any) -> str:
    if x is None:
        return ""
    if isinstance(x, float):
        return f"{x:.6g}"
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
