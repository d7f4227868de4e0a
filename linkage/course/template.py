"""Course-assignment templates: a scheme whose numbers are expressions of parameters.

A template is a scheme file (``schemes/README.md``) with an extra ``[template]`` table that
declares parameters (grids, lists, derived expressions, constants), the sheet's list of tasks and
feasibility rules; any string value of the scheme that starts with ``=`` is an expression of the
parameters. The format is documented in ``docs/templates.md``; the shipped templates are in
``schemes/templates/``.

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

import ast
import copy
import csv
import difflib
import graphlib
import io
import itertools
import keyword
import math
import numbers
import operator
import tomllib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, SchemeError
from ..model.mechanism import Mechanism, unknown_keys
from ..model.scheme import _schemes_dirs, from_dict, read_text, shipped_or_path

__all__ = [
    "DEFAULT_TASKS",
    "FUNCTIONS",
    "Parameter",
    "Template",
    "draws",
    "given_variants",
    "load_template",
    "loads_template",
    "shipped_templates",
]

#: the functions an expression may call: name -> (function, smallest and largest argument count)
FUNCTIONS: dict[str, tuple[Callable[..., Any], int, int]] = {
    "sqrt": (math.sqrt, 1, 1), "sin": (math.sin, 1, 1), "cos": (math.cos, 1, 1), "tan": (math.tan, 1, 1),
    "asin": (math.asin, 1, 1), "acos": (math.acos, 1, 1), "atan": (math.atan, 1, 1),
    "atan2": (math.atan2, 2, 2), "radians": (math.radians, 1, 1), "degrees": (math.degrees, 1, 1),
    "abs": (abs, 1, 1), "min": (min, 1, 64), "max": (max, 1, 64), "round": (round, 1, 2),
}
#: the constants an expression may use besides the parameters
CONSTANTS = {"pi": math.pi}
#: the sheet's tasks when a template gives none
DEFAULT_TASKS = (
    "Draw the mechanism to scale at the positions of the table",
    "Kinematic analysis: positions, velocities and accelerations of the output at the table positions",
    "Kinetostatic analysis: the reactions in the kinematic pairs and the balancing moment",
    "Size the flywheel for the given coefficient of speed fluctuation (Mertsalov's method)",
    "Find the law of motion of the input link: omega(phi) and epsilon(phi)",
)
TEMPLATE_KEYS = {"description", "tasks", "parameters", "require"}
PARAMETER_KEYS = {"range", "step", "values", "value", "unit", "label", "round"}
#: a grid larger than this is refused (a typo in a step, most likely)
MAX_GRID = 100_000
#: an integer result beyond this becomes a float (no unbounded integer arithmetic)
_MAX_EXACT_INT = 2 ** 53
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: None}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_REFUSED = {ast.Attribute: "attribute access ('.')", ast.Subscript: "indexing ('[ ]')",
            ast.Lambda: "lambda", ast.Compare: "comparison", ast.BoolOp: "'and' / 'or'",
            ast.IfExp: "'if ... else'", ast.Mod: "'%'", ast.FloorDiv: "'//'", ast.Not: "'not'"}
_ALLOWED = ("numbers, parameter names, pi, + - * / ** (and unary -), parentheses and the functions "
            + " ".join(FUNCTIONS))


# ----------------------------------------------------------------------------------------------
# expressions
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Expression:
    """A parsed expression: its text (with the leading ``=``), tree and the parameter names it uses."""

    text: str
    tree: ast.expr
    names: frozenset[str]

    @property
    def alias(self) -> str | None:
        """The parameter name when the expression is a name alone (``= k``), else None."""
        return self.tree.id if isinstance(self.tree, ast.Name) else None


def is_expression(value: Any) -> bool:
    """True for a string that starts with ``=`` (an expression of the parameters)."""
    return isinstance(value, str) and value.startswith("=")


def _node_problem(node: ast.AST) -> str | None:
    """Why ``node`` is not allowed in an expression, or None when it is."""
    if isinstance(node, (ast.Expression, ast.Load)) or type(node) in _BINARY or type(node) in _UNARY:
        return None  # the operators themselves are judged with their BinOp / UnaryOp
    if isinstance(node, ast.Constant):
        ok = isinstance(node.value, (int, float)) and not isinstance(node.value, bool)
        return None if ok else f"the constant {node.value!r} (only numbers)"
    if isinstance(node, (ast.BinOp, ast.UnaryOp)):
        allowed = _BINARY if isinstance(node, ast.BinOp) else _UNARY
        op = type(node.op)
        return None if op in allowed else _REFUSED.get(op, f"the operator {op.__name__}")
    if isinstance(node, ast.Name):
        return f"the name {node.id!r}" if node.id.startswith("__") else None
    if isinstance(node, ast.Call):
        return _call_problem(node)
    return _REFUSED.get(type(node), f"{type(node).__name__}")


def _call_problem(node: ast.Call) -> str | None:
    if not isinstance(node.func, ast.Name):
        return "a call of something other than a function name"
    name = node.func.id
    if name not in FUNCTIONS:
        meant = difflib.get_close_matches(name, list(FUNCTIONS), n=1)
        return f"a call of {name!r}" + (f" (did you mean {meant[0]!r}?)" if meant else "")
    if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
        return f"keyword or starred arguments of {name}()"
    low, high = FUNCTIONS[name][1:]
    if not low <= len(node.args) <= high:
        wanted = str(low) if low == high else f"{low} to {high}"
        return f"{name}() with {len(node.args)} arguments (it takes {wanted})"
    return None


def parse_expression(text: str, where: str, known: Mapping[str, str], problems: list[str]) -> _Expression | None:
    """Parse ``text`` (``"= crank / ratio"``) into an expression, on the whitelist.

    Parameters
    ----------
    text : str
        The expression with its leading ``=``.
    where : str
        The entry, for messages (``"[template.parameters] rod"``, ``"links.2.length"``).
    known : mapping
        Parameter name -> its type (``"number"``, ``"string"``, ``"bool"``, ``"mixed"``): names
        that are not numbers may only stand alone (``= k``).
    problems : list of str
        Problems found are appended here; None is returned then.
    """
    body = text[1:].strip()
    try:
        tree = ast.parse(body, mode="eval").body
    except SyntaxError as exc:
        problems.append(f"{where}: {text!r} is not a valid expression ({exc.msg}); allowed: {_ALLOWED}")
        return None
    found = list(dict.fromkeys(p for p in map(_node_problem, ast.walk(tree)) if p))
    if found:
        problems.append(f"{where}: {text!r} uses {', '.join(found)}, which {'is' if len(found) == 1 else 'are'} not "
                        f"allowed; allowed: {_ALLOWED}")
        return None
    functions = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and id(n) not in functions}
    before = len(problems)
    for name in sorted(names - set(known) - set(CONSTANTS)):
        meant = difflib.get_close_matches(name, [*known, *CONSTANTS], n=1)
        hint = f"; did you mean {meant[0]!r}?" if meant else f" (the parameters: {', '.join(known) or 'none'})"
        problems.append(f"{where}: unknown name {name!r} in {text!r}{hint}")
    if not isinstance(tree, ast.Name):
        for name in sorted(n for n in names if known.get(n, "number") != "number"):
            problems.append(f"{where}: {text!r}: the parameter {name!r} holds {known[name]} values, which can only "
                            f"be used alone (\"= {name}\"), not in arithmetic")
    if len(problems) > before:
        return None
    return _Expression(text, tree, frozenset(names))


def _number(value: Any) -> Any:
    """Python int or float of a number; an int beyond 2**53 becomes a float."""
    if isinstance(value, int) and abs(value) > _MAX_EXACT_INT:
        return float(value)
    return value


def _power(base: Any, exponent: Any) -> Any:
    if isinstance(base, int) and isinstance(exponent, int) and 0 <= exponent <= 64:
        return _number(base ** exponent)
    return math.pow(base, exponent)  # raises on a negative base with a fractional exponent


def _evaluate(node: ast.expr, env: Mapping[str, Any]) -> Any:
    """Value of a whitelisted tree; raises ArithmeticError or ValueError on a domain error."""
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        return env[node.id] if node.id in env else CONSTANTS[node.id]
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)](_evaluate(node.operand, env))
    if isinstance(node, ast.BinOp):
        left, right = _evaluate(node.left, env), _evaluate(node.right, env)
        if isinstance(node.op, ast.Pow):
            return _power(left, right)
        return _number(_BINARY[type(node.op)](left, right))
    if isinstance(node, ast.Call):
        args = [_evaluate(a, env) for a in node.args]
        if node.func.id == "round" and len(args) == 2:
            args[1] = int(args[1])
        return _number(FUNCTIONS[node.func.id][0](*args))
    raise AssertionError(f"not whitelisted: {ast.dump(node)}")  # parse_expression refused it


def _format(value: Any) -> str:
    return f"{value:.10g}" if isinstance(value, float) else str(value)


def _evaluated(expr: _Expression, env: Mapping[str, Any], where: str, free: Mapping[str, Any]) -> Any:
    """The value of ``expr``; an InputError naming ``where`` and the values when it is not finite."""
    try:
        value = _evaluate(expr.tree, env)
        reason = "" if not isinstance(value, float) or math.isfinite(value) else f"{value}"
    except (ArithmeticError, ValueError) as exc:
        value, reason = None, f"an error ({exc})"
    if reason:
        used = ", ".join(f"{n} = {_format(env[n])}" for n in sorted(expr.names) if n in env)
        draw = ", ".join(f"{n} = {_format(v)}" for n, v in free.items())
        raise InputError(f"{where}: {expr.text!r} gives {reason}, not a finite number, with {used or 'no names'} "
                         f"(free values: {draw or 'none'})")
    return value


# ----------------------------------------------------------------------------------------------
# parameters
# ----------------------------------------------------------------------------------------------


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
        return all(_is_plain_number(c) for c in self.choices)


def _is_plain_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _value_type(values) -> str:
    """``"number"``, ``"string"``, ``"bool"`` or ``"mixed"`` of a tuple of values."""
    kinds = {"number" if _is_plain_number(v) else "bool" if isinstance(v, bool) else "string" for v in values}
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
    return _is_plain_number(value) and math.isfinite(value)


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


def _types(parameters: tuple[Parameter, ...], derived: Mapping[str, _Expression],
           order: tuple[str, ...]) -> dict[str, str]:
    """Parameter name -> value type; a derived alias (``= k``) has the type of k, others are numbers."""
    types = {p.name: _value_type(p.choices) for p in parameters if p.kind != "derived"}
    for name in order:
        alias = derived[name].alias
        types[name] = types.get(alias, "number") if alias else "number"
    return types


def _derived_order(parameters: tuple[Parameter, ...], derived: Mapping[str, _Expression],
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


def _parse_parameters(raw: Any, problems: list[str]):
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


# ----------------------------------------------------------------------------------------------
# the scheme body
# ----------------------------------------------------------------------------------------------


def _path(where: str, key: Any) -> str:
    return f"{where}[{key}]" if isinstance(key, int) else (f"{where}.{key}" if where else str(key))


def _compile_body(value: Any, where: str, types: Mapping[str, str], problems: list[str]) -> Any:
    """The body with every expression string replaced by its parsed :class:`_Expression`."""
    if isinstance(value, Mapping):
        return {k: _compile_body(v, _path(where, k), types, problems) for k, v in value.items()}
    if isinstance(value, list):
        return [_compile_body(v, _path(where, i), types, problems) for i, v in enumerate(value)]
    if is_expression(value):
        return parse_expression(value, where, types, problems)
    return value


def _substitute(value: Any, env: Mapping[str, Any], where: str, free: Mapping[str, Any]) -> Any:
    """The compiled body with every expression replaced by its value."""
    if isinstance(value, Mapping):
        return {k: _substitute(v, env, _path(where, k), free) for k, v in value.items()}
    if isinstance(value, list):
        return [_substitute(v, env, _path(where, i), free) for i, v in enumerate(value)]
    if isinstance(value, _Expression):
        return _evaluated(value, env, where, free)
    return copy.deepcopy(value)


# ----------------------------------------------------------------------------------------------
# the template
# ----------------------------------------------------------------------------------------------


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
    """

    name: str
    description: str
    source: str
    parameters: tuple[Parameter, ...]
    free: tuple[str, ...]
    tasks: tuple[str, ...]
    require: dict
    body: dict
    _derived: Mapping[str, _Expression] = field(default_factory=dict, repr=False, compare=False)
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
            value = _evaluated(self._derived[name], env, f"{self._where()}[template.parameters] {name}", free)
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
        data = _substitute(self._compiled, env, "", free)
        data.pop("name", None)
        data.pop("description", None)
        return {"name": name or self.name, "description": self._described(self.description, free), **data}

    def _described(self, base: str, free: Mapping[str, Any]) -> str:
        parts = []
        for n, v in free.items():
            unit = self.parameter(n).unit
            parts.append(f"{n} = {_format(v)}{' ' + unit if unit else ''}")
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
            draw = ", ".join(f"{n} = {_format(v)}" for n, v in self._checked_free(free_values).items())
            raise SchemeError([f"{self.source} ({draw}): {p}" for p in exc.problems]) from None


def _hint(name: str, known) -> str:
    meant = difflib.get_close_matches(name, list(known), n=1)
    return f"; did you mean {meant[0]!r}?" if meant else f" (known: {', '.join(known) or 'none'})"


def _converted(p: Parameter, value: Any) -> tuple[Any, str]:
    """``(value as a Python number or string, problem or "")`` for the free parameter ``p``."""
    kind = _value_type(p.choices)
    if _is_plain_number(value):
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
    parameters, derived, order, types = _parse_parameters(table.get("parameters"), problems)
    tasks = _tasks(table.get("tasks"), problems)
    require = _require(table.get("require"), problems)
    description = _text(table.get("description"), "[template] description", problems) \
        or _text(body.get("description"), "description", problems)
    name = _text(body.get("name"), "name", problems) or default_name
    compiled = _compile_body(body, "", types, problems) if types is not None else {}
    if problems:
        raise SchemeError([f"{source}: {p}" for p in problems])
    return Template(name, description, source, parameters, tuple(p.name for p in parameters if p.free), tasks,
                    require, body, derived, order, compiled)


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
    for folder in _schemes_dirs():
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
    kind = _value_type(p.choices)
    if kind == "string":
        return text, ""
    try:
        number = float(text.replace(",", ".") if decimal_comma else text)
    except ValueError:
        return (text, "") if kind == "mixed" else (text, "is not a number")
    if not math.isfinite(number):
        return text, "is not a finite number"
    integral = all(isinstance(c, int) for c in p.choices) and number.is_integer() and abs(number) < _MAX_EXACT_INT
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
    """The variants of a teacher's table: ``[(label, free values), ...]`` in the file's order.

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
    variants: list[tuple[str, dict[str, Any]]] = []
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
        variants.append((label, values))
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
