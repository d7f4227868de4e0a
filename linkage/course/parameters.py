"""The parameters of a course template: its ``[template.parameters]`` table.

A parameter is free (a grid ``range = [a, b]`` with a ``step``, or a list of ``values``: what a
variant chooses), derived (an expression of other parameters, ``value = "= ..."``, evaluated in
an order where each follows those it uses) or a constant (:class:`Parameter`). This module reads
the table into parameters, checks their names, grids and lists, orders the derived ones and
tells the type of each one's values (numbers, strings, booleans); ``docs/templates.md``
documents the format.
"""

from __future__ import annotations

import graphlib
import keyword
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from decimal import Decimal
from typing import Any

from ..model.numbers import unknown_keys
from .expressions import CONSTANTS, FUNCTIONS, Expression, is_expression, parse_expression

__all__ = ["MAX_GRID", "Parameter", "grid", "is_plain_number", "parse_parameters", "value_type"]

PARAMETER_KEYS = {"range", "step", "values", "value", "unit", "label", "round"}
#: a grid larger than this is refused (a typo in a step, most likely)
MAX_GRID = 100_000


@dataclass(frozen=True)
class Parameter:
    """A parameter of a template.

    Attributes
    ----------
    name : str
        The name expressions use.
    kind : {"range", "values", "derived", "constant"}
        A grid ``range = [a, b]`` with a ``step``, a list ``values``, an expression of other
        parameters, or a constant.
    unit, label : str
        For the assignment sheet (``"m"``, ``"crank length OA"``); may be empty.
    choices : tuple
        The grid or the list of a free parameter (range, values); the one value of a constant;
        empty for a derived one.
    expression : str or None
        The expression of a derived parameter, with its ``=``.
    round : int or None
        Decimals a derived value is rounded to.
    """

    name: str
    kind: str
    unit: str = ""
    label: str = ""
    choices: tuple = ()
    expression: str | None = None
    round: int | None = None

    @property
    def free(self) -> bool:
        """True for a parameter a variant chooses (a range or a list)."""
        return self.kind in ("range", "values")

    @property
    def numeric(self) -> bool:
        """True when every choice (or the constant) is a number; derived ones count as numbers."""
        return all(is_plain_number(c) for c in self.choices)


def is_plain_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def value_type(values) -> str:
    """``"number"``, ``"string"``, ``"bool"`` or ``"mixed"`` of a tuple of values."""
    kinds = {"number" if is_plain_number(v) else "bool" if isinstance(v, bool) else "string" for v in values}
    return kinds.pop() if len(kinds) == 1 else "mixed"


def _decimals(x: float) -> int:
    """Decimals of the shortest text of ``x`` (0.005 -> 3, 1e-05 -> 5, 2 -> 0)."""
    return max(0, -Decimal(repr(x)).as_tuple().exponent)


def grid(start: float, stop: float, step: float) -> tuple:
    """The grid ``start, start + step, ... <= stop``, inclusive of ``stop`` up to rounding.

    Values are rounded to the decimals of ``step`` (or of ``start`` when it has more); all ints
    give ints.

    >>> grid(0.06, 0.08, 0.005)
    (0.06, 0.065, 0.07, 0.075, 0.08)
    >>> grid(0.1, 0.3, 0.1), grid(2, 7, 2)
    ((0.1, 0.2, 0.3), (2, 4, 6))
    """
    count = math.floor((stop - start) / step * (1 + 1e-12) + 1e-9) + 1
    if all(isinstance(v, int) and not isinstance(v, bool) for v in (start, stop, step)):
        return tuple(start + k * step for k in range(count))
    places = max(_decimals(float(step)), _decimals(float(start)))
    return tuple(dict.fromkeys(round(start + k * step, places) for k in range(count)))


def _finite_number(value: Any) -> bool:
    return is_plain_number(value) and math.isfinite(value)


def _grid_parameter(name: str, spec: Mapping[str, Any], where: str, problems: list[str]) -> tuple | None:
    """The choices of ``range = [a, b]``, ``step = h``; None (with a problem) when invalid."""
    span, step = spec.get("range"), spec.get("step")
    if not (isinstance(span, list) and len(span) == 2 and all(map(_finite_number, span))):
        problems.append(f"{where}: range must be [a, b], two finite numbers, got {span!r}")
        return None
    if "step" not in spec:
        problems.append(f"{where}: a range needs a step (the grid is a, a + step, ... <= b)")
        return None
    if not _finite_number(step) or step <= 0:
        problems.append(f"{where}: step must be > 0, got {step!r}")
        return None
    a, b = span
    if a > b:
        problems.append(f"{where}: range {span!r} gives an empty grid (a > b; write [a, b] with a <= b)")
        return None
    if (b - a) / step + 1 > MAX_GRID:
        problems.append(f"{where}: range {span!r} with step {step!r} gives {int((b - a) / step) + 1} values, more "
                        f"than {MAX_GRID}; check the step")
        return None
    return grid(a, b, step)


def _list_parameter(name: str, values: Any, where: str, problems: list[str]) -> tuple | None:
    """The choices of ``values = [...]``: numbers (finite) or strings, no repeats."""
    if not isinstance(values, list) or not values:
        problems.append(f"{where}: values must be a non-empty list of numbers or strings, got {values!r}")
        return None
    bad = [v for v in values if not (_finite_number(v) or isinstance(v, str))]
    if bad:
        problems.append(f"{where}: values must be finite numbers or strings, got {bad[0]!r} in {values!r}")
        return None
    repeated = sorted({repr(v) for v in values if values.count(v) > 1})
    if repeated:
        problems.append(f"{where}: values repeats {', '.join(repeated)} (every variant must be distinct)")
        return None
    return tuple(values)


def _check_name(name: str, where: str, problems: list[str]) -> bool:
    if not name.isidentifier() or keyword.iskeyword(name) or name.startswith("__"):
        problems.append(f"{where}: a parameter name must be a Python-style identifier (letters, digits, _), "
                        f"got {name!r}")
        return False
    if name in FUNCTIONS or name in CONSTANTS or name == "variant":
        problems.append(f"{where}: {name!r} is reserved (a function, pi, or the CSV column 'variant'); rename "
                        "the parameter")
        return False
    return True


def _table_parameter(name: str, spec: Mapping[str, Any], where: str, problems: list[str]):
    """A parameter written as a table: ``(Parameter, expression text or None)`` or None."""
    if unknown_keys(spec, PARAMETER_KEYS, where, problems):
        return None
    given = [k for k in ("range", "values", "value") if k in spec]
    if len(given) != 1:
        problems.append(f"{where}: give exactly one of 'range' (with 'step'), 'values' or 'value', got "
                        f"{given or 'none'}")
        return None
    texts = {k: spec.get(k, "") for k in ("unit", "label")}
    for key, text in texts.items():
        if not isinstance(text, str):
            problems.append(f"{where}: {key} must be a string, got {text!r}")
            return None
    if "step" in spec and given != ["range"]:
        problems.append(f"{where}: 'step' goes with 'range' only")
        return None
    rounding = spec.get("round")
    derived = given == ["value"] and is_expression(spec["value"])
    if rounding is not None and not derived:
        problems.append(f"{where}: 'round' applies to derived parameters (value = \"= ...\") only")
        return None
    if rounding is not None and not (isinstance(rounding, int) and not isinstance(rounding, bool)
                                     and 0 <= rounding <= 15):
        problems.append(f"{where}: round must be a whole number of decimals 0 ... 15, got {rounding!r}")
        return None
    if given == ["range"]:
        choices = _grid_parameter(name, spec, where, problems)
        return None if choices is None else Parameter(name, "range", choices=choices, **texts)
    if given == ["values"]:
        choices = _list_parameter(name, spec["values"], where, problems)
        return None if choices is None else Parameter(name, "values", choices=choices, **texts)
    return _value_parameter(name, spec["value"], where, problems, rounding, **texts)


def _value_parameter(name: str, value: Any, where: str, problems: list[str], rounding: int | None = None,
                     unit: str = "", label: str = "") -> Parameter | None:
    """A derived parameter (``"= ..."``) or a constant (a number, string or boolean)."""
    if is_expression(value):
        return Parameter(name, "derived", unit, label, expression=value, round=rounding)
    if isinstance(value, (str, bool)) or _finite_number(value):
        return Parameter(name, "constant", unit, label, choices=(value,))
    problems.append(f"{where}: expected a finite number, a string, a boolean, an expression \"= ...\" or a table "
                    f"{{range, step | values | value, unit, label}}, got {value!r}")
    return None


def _parameter(name: str, spec: Any, problems: list[str]) -> Parameter | None:
    where = f"[template.parameters] {name}"
    if not _check_name(name, where, problems):
        return None
    if isinstance(spec, Mapping):
        return _table_parameter(name, spec, where, problems)
    return _value_parameter(name, spec, where, problems)


def _types(parameters: tuple[Parameter, ...], derived: Mapping[str, Expression],
           order: tuple[str, ...]) -> dict[str, str]:
    """Parameter name -> value type; a derived alias (``= k``) has the type of k, others are numbers."""
    types = {p.name: value_type(p.choices) for p in parameters if p.kind != "derived"}
    for name in order:
        alias = derived[name].alias
        types[name] = types.get(alias, "number") if alias else "number"
    return types


def _derived_order(parameters: tuple[Parameter, ...], derived: Mapping[str, Expression],
                   problems: list[str]) -> tuple[str, ...]:
    """The derived parameters, each after those it uses; a cycle is a problem naming them."""
    names = {p.name for p in parameters if p.kind == "derived"}
    sorter = graphlib.TopologicalSorter({n: derived[n].names & names for n in names if n in derived})
    try:
        return tuple(sorter.static_order())
    except graphlib.CycleError as exc:
        cycle = list(reversed(exc.args[1]))
        if len(cycle) == 2:
            problems.append(f"[template.parameters] {cycle[0]}: the derived parameter uses itself")
        else:
            problems.append(f"[template.parameters]: the derived parameters {', '.join(sorted(set(cycle)))} depend "
                            f"on each other in a cycle ({' -> '.join(cycle)}; each uses the next)")
        return ()


def parse_parameters(raw: Any, problems: list[str]):
    """``(parameters, derived expressions, evaluation order, types)`` of ``[template.parameters]``;
    the types are None when a parameter has a problem (the body is not checked then)."""
    if raw is None:
        raw = {}
    if not isinstance(raw, Mapping):
        problems.append(f"[template.parameters]: expected a table of parameters, got {raw!r}")
        return (), {}, (), None
    parameters = tuple(p for p in (_parameter(n, s, problems) for n, s in raw.items()) if p is not None)
    if len(parameters) < len(raw):
        return parameters, {}, (), None
    loose = {p.name: "number" for p in parameters}  # types are checked once the order is known
    derived = {}
    for p in parameters:
        if p.kind == "derived":
            expr = parse_expression(p.expression, f"[template.parameters] {p.name}", loose, problems)
            if expr is not None:
                derived[p.name] = expr
    if len(derived) < sum(p.kind == "derived" for p in parameters):
        return parameters, derived, (), None
    order = _derived_order(parameters, derived, problems)
    if derived and not order:
        return parameters, derived, (), None
    types = _types(parameters, derived, order)
    before = len(problems)
    for name in order:
        where = f"[template.parameters] {name}"
        parse_expression(derived[name].text, where, types, problems)
        if types[name] != "number" and next(p for p in parameters if p.name == name).round is not None:
            problems.append(f"{where}: 'round' needs a number, but {derived[name].text!r} holds {types[name]} values")
    return parameters, derived, order, (types if len(problems) == before else None)
