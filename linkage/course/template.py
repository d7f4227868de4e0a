"""Course-assignment templates: a scheme whose numbers are expressions of parameters.

A template is a scheme file (``schemes/README.md``) with an extra ``[template]`` table that
declares parameters (grids, lists, derived expressions, constants), the sheet's list of tasks and
feasibility rules; any string value of the scheme that starts with ``=`` is an expression of the
parameters. The format is documented in ``docs/templates.md``; the shipped templates are in
``schemes/templates/``.

This module holds the :class:`Template` (a variant's values, scheme and mechanism), loading
templates (:func:`load_template`, :func:`loads_template`), reproducible draws of the free values
(:func:`draws`) and the teacher's table of given variants (:func:`given_variants`, a CSV). The
expressions are :mod:`~linkage.course.expressions`'s; the ``[template.parameters]`` table is read
by :mod:`~linkage.course.parameters`.

>>> from linkage.course.template import loads_template, draws
>>> t = loads_template('''
... name = "bar"
... input = "1"
... [links.0]
... points = { O = [0.0, 0.0] }
... [links.1]
... line = ["O", "A"]
... length = "= 2 * r"
... [pairs.O]
... links = ["0", "1"]
... [template.parameters]
... r = { range = [0.1, 0.3], step = 0.1, unit = "m" }
... ''')
>>> t.free, t.parameters[0].choices, t.size
(('r',), (0.1, 0.2, 0.3), 3)
>>> t.scheme_data({"r": 0.2})["links"]["1"]["length"]
0.4
>>> sorted(d["r"] for d in draws(t, seed=1))
[0.1, 0.2, 0.3]
"""


from __future__ import annotations

import copy
import csv
import difflib
import fnmatch
import io
import itertools
import math
import numbers
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, SchemeError
from ..model.mechanism import Mechanism
from ..model.numbers import unknown_keys
from ..model.scheme import from_dict, read_text, schemes_dirs, shipped_or_path
from .expressions import MAX_EXACT_INT, Expression, compile_body, evaluated, format_value, substitute
from .parameters import Parameter, is_plain_number, parse_parameters, value_type

__all__ = [
    "DEFAULT_TASKS",
    "Grading",
    "Template",
    "draws",
    "given_rows",
    "given_variants",
    "load_template",
    "loads_template",
    "quantity_names",
    "shipped_templates",
]

#: the sheet's tasks when a template gives none
DEFAULT_TASKS = (
    "Draw the mechanism to scale at the positions of the table",
    "Kinematic analysis: positions, velocities and accelerations of the output at the table positions",
    "Kinetostatic analysis: the reactions in the kinematic pairs and the balancing moment",
    "Size the flywheel for the given coefficient of speed fluctuation (Mertsalov's method)",
    "Find the law of motion of the input link: ω(φ) and ε(φ)",
)
TEMPLATE_KEYS = {"description", "tasks", "parameters", "require", "grading"}
GRADING_KEYS = {"tolerance", "digits", "points", "force_positions", "tolerances"}

#: the quantities of an answer key (:mod:`~linkage.course.key`, docs/templates.md): ``P.<q>`` of a
#: point P, ``L.<q>`` of a moving link L, ``K.<q>`` of a pair K, and the named ones
POINT_QUANTITIES = ("x", "y", "x'", "y'", "x''", "y''", "vx", "vy", "v", "ax", "ay", "a")
LINK_QUANTITIES = ("theta_deg", "theta'", "theta''", "omega", "eps")
PAIR_QUANTITIES = ("R", "angle_deg")
NAMED_QUANTITIES = (
    "balancing_moment", "lever_balancing_moment",
    "reduced_moment_resistance", "reduced_moment_driving", "reduced_inertia", "reduced_inertia_variable",
    "reduced_inertia_derivative", "work_resistance", "work_driving", "delta_T", "T_variable", "delta_T_prime",
    "omega", "eps",
    "driving_moment", "delta_T_prime_max", "delta_T_prime_min", "delta_T_prime_swing", "reduced_inertia_constant",
    "required_constant_inertia", "flywheel_inertia", "stroke",
)
#: characters that make a ``[template.grading] tolerances`` key a pattern
_WILDCARDS = set("*?[")


# ----------------------------------------------------------------------------------------------
# the template
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Grading:
    """How an answer key grades a student's numbers: ``[template.grading]`` (docs/templates.md).

    Attributes
    ----------
    tolerance : float
        Relative tolerance of every quantity without its own (0.02: 2 %).
    digits : int
        Significant digits a student reports.
    points : tuple of str or None
        The points whose positions, analogs, velocities and accelerations the key holds; None: the
        output point and the centres of mass of the moving links that are named points.
    force_positions : tuple of int or None
        Table positions (1 .. n+1) of the reactions and balancing moments; None: every position.
    tolerances : dict of str -> float
        Relative tolerance per quantity name (``"B.v"``) or pattern (``"*.R"``, shell-style).

    >>> Grading(tolerances={"*.R": 0.05, "B.R": 0.01}).tolerance_of("A.R")
    0.05
    >>> Grading(tolerances={"*.R": 0.05, "B.R": 0.01}).tolerance_of("B.R"), Grading().tolerance_of("B.v")
    (0.01, 0.02)
    """

    tolerance: float = 0.02
    digits: int = 4
    points: tuple[str, ...] | None = None
    force_positions: tuple[int, ...] | None = None
    tolerances: Mapping[str, float] = field(default_factory=dict)

    def tolerance_of(self, quantity: str) -> float:
        """The tolerance of ``quantity``: its own name in ``tolerances``, else the first pattern
        there that matches it (in the order written), else ``tolerance``."""
        if quantity in self.tolerances:
            return self.tolerances[quantity]
        for pattern, value in self.tolerances.items():
            if _WILDCARDS & set(pattern) and fnmatch.fnmatchcase(quantity, pattern):
                return value
        return self.tolerance


@dataclass(frozen=True)
class Template:
    """A course-assignment template: a scheme with parameters (see ``docs/templates.md``).

    Attributes
    ----------
    name : str
        The scheme's ``name`` (default: the file name without ``.toml``).
    description : str
        ``[template] description`` (else the scheme's ``description``).
    source : str
        The file it was read from, or ``"<string>"``.
    parameters : tuple of Parameter
        In declaration order.
    free : tuple of str
        The names of the free (range and values) parameters, in declaration order.
    tasks : tuple of str
        What the sheet asks to compute.
    require : dict
        ``[template.require]`` as written: feasibility rules another module checks.
    body : dict
        The scheme data without ``[template]``, expressions still as ``"= ..."`` strings.
    grading : Grading
        ``[template.grading]``: tolerances, digits and what the answer keys hold.
    """

    name: str
    description: str
    source: str
    parameters: tuple[Parameter, ...]
    free: tuple[str, ...]
    tasks: tuple[str, ...]
    require: dict
    body: dict
    grading: Grading = field(default_factory=Grading)
    _derived: Mapping[str, Expression] = field(default_factory=dict, repr=False, compare=False)
    _order: tuple[str, ...] = field(default=(), repr=False, compare=False)
    _compiled: Mapping[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def parameter(self, name: str) -> Parameter:
        """The parameter ``name``; InputError (with a did-you-mean) when there is none."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise InputError(f"template {self.name!r}: no parameter {name!r}{_hint(name, self._names())}")

    def _names(self) -> list[str]:
        return [p.name for p in self.parameters]

    @property
    def size(self) -> int:
        """The number of distinct combinations of the free parameters (product of choice counts)."""
        return math.prod(len(self.parameter(n).choices) for n in self.free)

    def values(self, free_values: Mapping[str, Any]) -> dict[str, Any]:
        """Every parameter's value (free, derived, constants), in declaration order.

        Parameters
        ----------
        free_values : mapping
            One value per free parameter. Values outside the grid are accepted (given variants);
            a numeric parameter needs a finite number.

        Raises
        ------
        InputError
            A free parameter missing or unknown, a value of the wrong type, or a derived
            expression that gives no finite number (naming the parameter and the values).
        """
        free = self._checked_free(free_values)
        env = {p.name: p.choices[0] for p in self.parameters if p.kind == "constant"}
        env.update(free)
        for name in self._order:
            p = self.parameter(name)
            value = evaluated(self._derived[name], env, f"{self._where()}[template.parameters] {name}", free)
            env[name] = round(value, p.round) if p.round is not None else value
        return {p.name: env[p.name] for p in self.parameters}

    def _where(self) -> str:
        return f"{self.source}: "

    def _checked_free(self, free_values: Mapping[str, Any]) -> dict[str, Any]:
        """The free values in declaration order, as Python numbers or strings."""
        unknown = [k for k in free_values if k not in self.free]
        missing = [n for n in self.free if n not in free_values]
        problems = [f"{k!r} is not a free parameter (it is {self.parameter(k).kind}: the template gives its value)"
                    if k in self._names() else f"unknown free parameter {k!r}{_hint(str(k), self.free)}"
                    for k in unknown]
        if missing:
            problems.append(f"no value for the free parameters {missing}")
        checked = {}
        for name in self.free:
            if name in free_values:
                value, problem = _converted(self.parameter(name), free_values[name])
                checked[name] = value
                if problem:
                    problems.append(problem)
        if problems:
            raise InputError(f"template {self.name!r}: " + "; ".join(problems))
        return checked

    def scheme_data(self, free_values: Mapping[str, Any], name: str | None = None) -> dict[str, Any]:
        """The scheme of one variant as plain data, every expression replaced by its value.

        ``name`` (default: the template's name) becomes the scheme's name; its description is
        the template's with the free values appended. :func:`linkage.model.scheme.from_dict` accepts
        the result and :func:`linkage.model.scheme.toml_text` writes it as a plain scheme file.
        """
        env = self.values(free_values)
        free = {n: env[n] for n in self.free}
        data = substitute(self._compiled, env, "", free)
        data.pop("name", None)
        data.pop("description", None)
        return {"name": name or self.name, "description": self._described(self.description, free), **data}

    def _described(self, base: str, free: Mapping[str, Any]) -> str:
        parts = []
        for n, v in free.items():
            unit = self.parameter(n).unit
            parts.append(f"{n} = {format_value(v)}{' ' + unit if unit else ''}")
        values = ", ".join(parts)
        return f"{base} ({values})" if base and values else base or values

    def mechanism(self, free_values: Mapping[str, Any], name: str | None = None) -> Mechanism:
        """The :class:`~linkage.model.mechanism.Mechanism` of one variant (built by ``linkage.model.scheme.from_dict``).

        Raises
        ------
        SchemeError
            The variant's scheme is invalid; every problem is prefixed with the template and the
            free values.
        """

        data = self.scheme_data(free_values, name)
        try:
            return from_dict(data, default_name=data["name"])
        except SchemeError as exc:
            draw = ", ".join(f"{n} = {format_value(v)}" for n, v in self._checked_free(free_values).items())
            raise SchemeError([f"{self.source} ({draw}): {p}" for p in exc.problems]) from None


def _hint(name: str, known) -> str:
    meant = difflib.get_close_matches(name, list(known), n=1)
    return f"; did you mean {meant[0]!r}?" if meant else f" (known: {', '.join(known) or 'none'})"


def _converted(p: Parameter, value: Any) -> tuple[Any, str]:
    """``(value as a Python number or string, problem or "")`` for the free parameter ``p``."""
    kind = value_type(p.choices)
    if is_plain_number(value):
        number = value.item() if isinstance(value, np.generic) else value
        if kind == "string":
            return value, f"{p.name}: expected one of the strings {list(p.choices)}, got {value!r}"
        if not math.isfinite(number):
            return value, f"{p.name}: expected a finite number, got {value!r}"
        return (int(number) if isinstance(number, numbers.Integral) else float(number)), ""
    if isinstance(value, str) and kind in ("string", "mixed"):
        return value, ""
    return value, f"{p.name}: expected {'a number' if kind == 'number' else 'a number or a string'}, got {value!r}"


# ----------------------------------------------------------------------------------------------
# loading
# ----------------------------------------------------------------------------------------------


def _template_table(raw: Any, problems: list[str]) -> Mapping[str, Any]:
    if not isinstance(raw, Mapping):
        problems.append("not a template: a template has a [template] table (with [template.parameters]); a plain "
                        "scheme loads with linkage.load" if raw is None else
                        f"[template]: expected a table, got {raw!r}")
        return {}
    unknown_keys(raw, TEMPLATE_KEYS, "[template]", problems)
    return raw


def _tasks(raw: Any, problems: list[str]) -> tuple[str, ...]:
    if raw is None:
        return DEFAULT_TASKS
    if not (isinstance(raw, list) and all(isinstance(t, str) and t.strip() for t in raw)):
        problems.append(f"[template] tasks: expected a list of non-empty strings, got {raw!r}")
        return ()
    return tuple(raw)


def _require(raw: Any, problems: list[str]) -> dict:
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        problems.append(f"[template.require]: expected a table of rules (key = value), got {raw!r}")
        return {}
    return copy.deepcopy(dict(raw))


def _scheme_names(body: Mapping[str, Any]) -> tuple[list[str], list[str], list[str]]:
    """The point names, moving link names and pair names the template's scheme declares (a
    link's ``line`` and ``points``; expressions and malformed entries left out)."""
    links = body.get("links") if isinstance(body.get("links"), Mapping) else {}
    points: set[str] = set()
    for spec in links.values():
        if not isinstance(spec, Mapping):
            continue
        line = spec.get("line") if isinstance(spec.get("line"), list) else []
        table = spec.get("points") if isinstance(spec.get("points"), Mapping) else {}
        points.update(p for p in [*line, *table] if isinstance(p, str) and not p.startswith("="))
    frame = str(body.get("frame", "0"))
    pairs = body.get("pairs") if isinstance(body.get("pairs"), Mapping) else {}
    return sorted(points), sorted(str(k) for k in links if str(k) != frame), sorted(str(k) for k in pairs)


def _table_rows(body: Mapping[str, Any]) -> int | None:
    """The number of rows of the template's tables (positions + 1), when the scheme gives its
    ``[dynamics] positions`` as a number (12 positions without ``[dynamics]``); None when an
    expression gives it (checked per variant)."""
    dynamics = body.get("dynamics")
    if not isinstance(dynamics, Mapping) or "positions" not in dynamics:
        return 13
    n = dynamics["positions"]
    return n + 1 if isinstance(n, int) and not isinstance(n, bool) and n >= 1 else None


def _fraction(raw: Any, where: str, problems: list[str]) -> float | None:
    if is_plain_number(raw) and math.isfinite(raw) and 0 < raw <= 1:
        return float(raw)
    problems.append(f"{where}: expected a relative tolerance, a number in (0, 1] (0.02 is 2 %), got {raw!r}")
    return None


def _distinct_list(raw: Any, where: str, what: str, problems: list[str]) -> list | None:
    """A list of distinct entries, or None with a problem."""
    if not isinstance(raw, list):
        problems.append(f"{where}: expected a list of {what}, got {raw!r}")
        return None
    repeated = sorted({repr(x) for x in raw if raw.count(x) > 1})
    if repeated:
        problems.append(f"{where}: {', '.join(repeated)} listed more than once")
    return raw


def quantity_names(points, links, pairs) -> list[str]:
    """Every quantity name an answer key of a scheme with these points, moving links and pairs may
    hold (:data:`POINT_QUANTITIES` ... :data:`NAMED_QUANTITIES`)."""
    return ([f"{p}.{q}" for p in points for q in POINT_QUANTITIES] + [f"{k}.{q}" for k in links for q in LINK_QUANTITIES]
            + [f"{k}.{q}" for k in pairs for q in PAIR_QUANTITIES] + list(NAMED_QUANTITIES))


def _grading(raw: Any, body: Mapping[str, Any], problems: list[str]) -> Grading:
    """``[template.grading]`` read and checked against the template's scheme."""
    if raw is None:
        return Grading()
    where = "[template.grading]"
    if not isinstance(raw, Mapping):
        problems.append(f"{where}: expected a table (tolerance, digits, points, force_positions, tolerances), "
                        f"got {raw!r}")
        return Grading()
    unknown_keys(raw, GRADING_KEYS, where, problems)
    points, links, pairs = _scheme_names(body)
    found: dict[str, Any] = {}
    if "tolerance" in raw:
        found["tolerance"] = _fraction(raw["tolerance"], f"{where} tolerance", problems)
    if "digits" in raw:
        digits = raw["digits"]
        if isinstance(digits, int) and not isinstance(digits, bool) and 1 <= digits <= 15:
            found["digits"] = digits
        else:
            problems.append(f"{where} digits: expected a whole number of significant digits, 1 .. 15, got {digits!r}")
    if "points" in raw:
        names = _distinct_list(raw["points"], f"{where} points", "point names", problems)
        for name in names or ():
            if not isinstance(name, str) or name not in points:
                problems.append(f"{where} points: {name!r} is not a point of the scheme"
                                f"{_hint(str(name), points)}")
        found["points"] = tuple(names) if names is not None else None
    if "force_positions" in raw:
        rows = _table_rows(body)
        numbers = _distinct_list(raw["force_positions"], f"{where} force_positions", "table positions (whole numbers)",
                         problems)
        for k in numbers or ():
            whole = isinstance(k, int) and not isinstance(k, bool)
            if not whole or k < 1 or (rows is not None and k > rows):
                span = f"1 .. {rows}: the scheme's {rows - 1} positions and position {rows}, the end of the cycle" \
                    if rows is not None else "whole numbers from 1"
                problems.append(f"{where} force_positions: {k!r} is not a table position ({span})")
        found["force_positions"] = tuple(numbers) if numbers is not None else None
    if "tolerances" in raw:
        table = raw["tolerances"]
        if not isinstance(table, Mapping):
            problems.append(f"{where} tolerances: expected a table of quantity = relative tolerance "
                            f"(\"B.v\" = 0.01, \"*.R\" = 0.05), got {table!r}")
            table = {}
        known = quantity_names(points, links, pairs)
        tolerances = {}
        for name, value in table.items():
            if _WILDCARDS & set(name):
                if not any(fnmatch.fnmatchcase(q, name) for q in known):
                    problems.append(f"{where} tolerances: the pattern {name!r} matches no quantity of the key")
            elif name not in known:
                meant = difflib.get_close_matches(name, known, n=1)
                hint = f"; did you mean {meant[0]!r}?" if meant else " (docs/templates.md lists the quantities)"
                problems.append(f"{where} tolerances: {name!r} is not a quantity of the key{hint}")
            tolerance = _fraction(value, f"{where} tolerances {name!r}", problems)
            if tolerance is not None:
                tolerances[name] = tolerance
        found["tolerances"] = tolerances
    return Grading(**{k: v for k, v in found.items() if v is not None})


def _text(raw: Any, where: str, problems: list[str]) -> str:
    if raw is None:
        return ""
    if not isinstance(raw, str):
        problems.append(f"{where}: expected a string, got {raw!r}")
        return ""
    return raw


def _template_from_data(data: Mapping[str, Any], source: str, default_name: str) -> Template:
    """Build a template from parsed TOML; SchemeError listing every problem, prefixed by ``source``."""
    problems: list[str] = []
    body = {k: copy.deepcopy(v) for k, v in data.items() if k != "template"}
    table = _template_table(data.get("template"), problems)
    parameters, derived, order, types = parse_parameters(table.get("parameters"), problems)
    tasks = _tasks(table.get("tasks"), problems)
    require = _require(table.get("require"), problems)
    grading = _grading(table.get("grading"), body, problems)
    description = _text(table.get("description"), "[template] description", problems) \
        or _text(body.get("description"), "description", problems)
    name = _text(body.get("name"), "name", problems) or default_name
    compiled = compile_body(body, "", types, problems) if types is not None else {}
    if problems:
        raise SchemeError([f"{source}: {p}" for p in problems])
    return Template(name, description, source, parameters, tuple(p.name for p in parameters if p.free), tasks,
                    require, body, grading, derived, order, compiled)


def loads_template(text: str, source: str = "<string>") -> Template:
    """Parse a template given as TOML text (``source`` names it in errors and is kept).

    Raises
    ------
    SchemeError
        Malformed TOML, or every problem of the ``[template]`` table and of the expressions,
        each naming the source, the entry and the value.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SchemeError(f"{source}: malformed TOML: {exc}") from None
    default = Path(source).stem if source != "<string>" else "template"
    return _template_from_data(data, source, default)


def shipped_templates() -> dict[str, Path]:
    """Shipped template names -> files (``schemes/templates/*.toml``), sorted by name."""

    found: dict[str, Path] = {}
    for folder in schemes_dirs():
        for path in sorted((folder / "templates").glob("*.toml")):
            found.setdefault(path.stem, path)
    return dict(sorted(found.items()))


def template_path(name_or_path: str | Path) -> Path:
    """The file of a shipped template name, or the given path."""

    return shipped_or_path(name_or_path, shipped_templates(), "template")


def load_template(name_or_path: str | Path) -> Template:
    """Load a shipped template by name (``"press_slider_crank"``) or any template file by path.

    Raises
    ------
    SchemeError
        An unknown name, an unreadable file, or every problem of the template.
    """

    path = template_path(name_or_path)
    return loads_template(read_text(path, "template"), source=str(path))


# ----------------------------------------------------------------------------------------------
# variants
# ----------------------------------------------------------------------------------------------


def draws(template: Template, seed: int) -> Iterator[dict[str, Any]]:
    """A reproducible stream of distinct combinations of the free parameters.

    Each draw takes one index per free parameter, in declaration order, from
    ``numpy.random.default_rng(seed)``; a combination drawn before is skipped. Once half of the
    grid is drawn the rest is listed and shuffled with the same generator, so the stream stays
    cheap to the end and stops after every combination was drawn once. The same seed gives the
    same sequence.

    Yields
    ------
    dict
        Free parameter name -> value, in declaration order.
    """
    choices = [template.parameter(n).choices for n in template.free]
    counts = np.array([len(c) for c in choices], dtype=np.int64)
    size = template.size
    rng = np.random.default_rng(seed)
    drawn: set[tuple[int, ...]] = set()

    def combination(index: tuple[int, ...]) -> dict[str, Any]:
        return {n: c[i] for n, c, i in zip(template.free, choices, index)}

    while 2 * len(drawn) < size:
        index = tuple(int(i) for i in rng.integers(0, counts)) if len(counts) else ()
        if index not in drawn:
            drawn.add(index)
            yield combination(index)
    rest = [i for i in itertools.product(*(range(c) for c in counts)) if i not in drawn]
    for k in rng.permutation(len(rest)):
        yield combination(rest[k])


def _delimiter(header: str) -> str:
    """The CSV delimiter of a header line: the most frequent of ``,`` ``;`` and tab."""
    counts = {d: header.count(d) for d in (",", ";", "\t")}
    best = max(counts, key=counts.get)
    return best if counts[best] else ","


def _cell_value(p: Parameter, text: str, decimal_comma: bool) -> tuple[Any, str]:
    """``(value, problem or "")`` of a CSV cell for the free parameter ``p``."""
    kind = value_type(p.choices)
    if kind == "string":
        return text, ""
    try:
        number = float(text.replace(",", ".") if decimal_comma else text)
    except ValueError:
        return (text, "") if kind == "mixed" else (text, "is not a number")
    if not math.isfinite(number):
        return text, "is not a finite number"
    integral = all(isinstance(c, int) for c in p.choices) and number.is_integer() and abs(number) < MAX_EXACT_INT
    return (int(number) if integral else number), ""


def _csv_header(header: list[str], template: Template, where: str) -> tuple[list[str], int | None]:
    """The stripped column names and the index of ``variant``; InputError on unknown or missing columns."""
    names = [h.strip() for h in header]
    problems = []
    labels = [i for i, h in enumerate(names) if h.lower() == "variant"]
    known = [*template.free, "variant"]
    for h in names:
        if h.lower() != "variant" and h not in template.free:
            what = "a parameter computed by the template" if h in template._names() else "unknown"
            problems.append(f"column {h!r} is {what}{_hint(h, known)}")
    repeated = sorted({h for h in names if names.count(h) > 1})
    if repeated:
        problems.append(f"columns {repeated} appear more than once")
    missing = [n for n in template.free if n not in names]
    if missing:
        problems.append(f"no column for the free parameters {missing}")
    if problems:
        raise InputError(f"{where}: header: " + "; ".join(problems) + f" (the columns are 'variant' (optional) and "
                         f"the free parameters {list(template.free)})")
    return names, (labels[0] if labels else None)


def _read_rows(path: Path) -> tuple[list[tuple[int, list[str]]], str]:
    """``([(line number, cells), ...], delimiter)`` of a CSV file, blank and ``#`` lines left out."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot be read as UTF-8 text ({exc})") from None
    first = next((line for line in text.splitlines() if line.strip()), "")
    delimiter = _delimiter(first)
    reader = csv.reader(io.StringIO(text), delimiter=delimiter)
    rows = []
    for cells in reader:
        if any(c.strip() for c in cells) and not cells[0].lstrip().startswith("#"):
            rows.append((reader.line_num, cells))
    if not rows:
        raise InputError(f"{path}: empty: expected a header (the free parameters, optionally 'variant') and one "
                         "row per variant")
    return rows, delimiter


def given_variants(template: Template, csv_path: str | Path) -> list[tuple[str, dict[str, Any]]]:
    """The variants of a teacher's table: ``[(label, free values), ...]`` in the file's order
    (:func:`given_rows` without the lines)."""
    return [(label, values) for _, label, values in given_rows(template, csv_path)]


def given_rows(template: Template, csv_path: str | Path) -> list[tuple[int, str, dict[str, Any]]]:
    """The variants of a teacher's table: ``[(line, label, free values), ...]`` in the file's
    order, ``line`` the row's line number in the file (1: the header).

    The CSV has a header with one column per free parameter and optionally ``variant`` (the
    label; default ``"1"``, ``"2"``, ...). Delimiter ``,`` (or ``;`` or tab, then a decimal
    comma is accepted). Values may lie off the grid, but a numeric parameter needs a finite
    number; every row's derived values must be finite too.

    Raises
    ------
    InputError
        Every problem, naming the file, the line, the column and the value; unknown or missing
        columns with a did-you-mean.
    """
    path = Path(csv_path)
    rows, delimiter = _read_rows(path)
    (_, header), data = rows[0], rows[1:]
    names, label_column = _csv_header(header, template, str(path))
    problems: list[str] = []
    variants: list[tuple[int, str, dict[str, Any]]] = []
    seen: dict[str, int] = {}
    for count, (line, cells) in enumerate(data, start=1):
        where = f"{path}: line {line}"
        if len(cells) != len(names):
            problems.append(f"{where}: {len(cells)} cells, the header has {len(names)}")
            continue
        label = cells[label_column].strip() if label_column is not None else str(count)
        values, found = _row_values(template, names, cells, where, delimiter != ",")
        if label_column is not None and not label:
            found.append(f"{where}, column 'variant': empty label")
        elif label in seen:
            found.append(f"{where}, column 'variant': the label {label!r} repeats line {seen[label]}")
        seen.setdefault(label, line)
        if not found:
            found += _derived_problems(template, values, where)
        problems += found
        variants.append((line, label, values))
    if not data:
        problems.append(f"{path}: no variants: only a header")
    if problems:
        raise InputError("\n".join(problems))
    return variants


def _row_values(template: Template, names: list[str], cells: list[str], where: str,
                decimal_comma: bool) -> tuple[dict[str, Any], list[str]]:
    """The free values of one CSV row (declaration order) and the problems of its cells."""
    values, problems = {}, []
    by_name = dict(zip(names, cells))
    for name in template.free:
        text = by_name[name].strip()
        if not text:
            problems.append(f"{where}, column {name!r}: empty cell")
            continue
        value, problem = _cell_value(template.parameter(name), text, decimal_comma)
        if problem:
            problems.append(f"{where}, column {name!r}: {text!r} {problem}")
        values[name] = value
    return values, problems


def _derived_problems(template: Template, values: Mapping[str, Any], where: str) -> list[str]:
    try:
        template.values(values)
    except InputError as exc:
        return [f"{where}: {exc}"]
    return []
