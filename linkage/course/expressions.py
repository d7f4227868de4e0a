"""The expression language of course templates: values computed from the parameters.

Any string value of a template's scheme (or of a derived parameter) that starts with ``=`` is an
expression: numbers, parameter names, ``pi``, ``+ - * / **`` and the functions of
:data:`FUNCTIONS`, nothing else (no attribute access, indexing or comparisons: the tree is
checked against a whitelist before it is ever evaluated, so a template cannot run code). Parsed
once (:func:`parse_expression`), evaluated for each variant (:func:`evaluated`), and applied to
the whole scheme body (:func:`compile_body`, then :func:`substitute`). The format is documented
in ``docs/templates.md``.

>>> problems = []
>>> expr = parse_expression("= 2 * r + sqrt(s)", "links.1.length", {"r": "number", "s": "number"}, problems)
>>> sorted(expr.names), evaluated(expr, {"r": 0.1, "s": 4.0}, "links.1.length", {})
(['r', 's'], 2.2)
>>> parse_expression("= r.real", "links.1.length", {"r": "number"}, problems) is None, len(problems)
(True, 1)
"""

from __future__ import annotations

import ast
import copy
import difflib
import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import InputError

__all__ = [
    "CONSTANTS",
    "FUNCTIONS",
    "MAX_EXACT_INT",
    "Expression",
    "compile_body",
    "evaluated",
    "format_value",
    "is_expression",
    "parse_expression",
    "substitute",
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
#: an integer result beyond this becomes a float (no unbounded integer arithmetic)
MAX_EXACT_INT = 2 ** 53
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: None}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_REFUSED = {ast.Attribute: "attribute access ('.')", ast.Subscript: "indexing ('[ ]')",
            ast.Lambda: "lambda", ast.Compare: "comparison", ast.BoolOp: "'and' / 'or'",
            ast.IfExp: "'if ... else'", ast.Mod: "'%'", ast.FloorDiv: "'//'", ast.Not: "'not'"}
_ALLOWED = ("numbers, parameter names, pi, + - * / ** (and unary -), parentheses and the functions "
            + " ".join(FUNCTIONS))


@dataclass(frozen=True)
class Expression:
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


def parse_expression(text: str, where: str, known: Mapping[str, str], problems: list[str]) -> Expression | None:
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
    return Expression(text, tree, frozenset(names))


def _number(value: Any) -> Any:
    """Python int or float of a number; an int beyond 2**53 becomes a float."""
    if isinstance(value, int) and abs(value) > MAX_EXACT_INT:
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


def format_value(value: Any) -> str:
    return f"{value:.10g}" if isinstance(value, float) else str(value)


def evaluated(expr: Expression, env: Mapping[str, Any], where: str, free: Mapping[str, Any]) -> Any:
    """The value of ``expr``; an InputError naming ``where`` and the values when it is not finite."""
    try:
        value = _evaluate(expr.tree, env)
        reason = "" if not isinstance(value, float) or math.isfinite(value) else f"{value}"
    except (ArithmeticError, ValueError) as exc:
        value, reason = None, f"an error ({exc})"
    if reason:
        used = ", ".join(f"{n} = {format_value(env[n])}" for n in sorted(expr.names) if n in env)
        draw = ", ".join(f"{n} = {format_value(v)}" for n, v in free.items())
        raise InputError(f"{where}: {expr.text!r} gives {reason}, not a finite number, with {used or 'no names'} "
                         f"(free values: {draw or 'none'})")
    return value


# ----------------------------------------------------------------------------------------------
# the scheme body
# ----------------------------------------------------------------------------------------------


def _path(where: str, key: Any) -> str:
    return f"{where}[{key}]" if isinstance(key, int) else (f"{where}.{key}" if where else str(key))


def compile_body(value: Any, where: str, types: Mapping[str, str], problems: list[str]) -> Any:
    """The body with every expression string replaced by its parsed :class:`Expression`."""
    if isinstance(value, Mapping):
        return {k: compile_body(v, _path(where, k), types, problems) for k, v in value.items()}
    if isinstance(value, list):
        return [compile_body(v, _path(where, i), types, problems) for i, v in enumerate(value)]
    if is_expression(value):
        return parse_expression(value, where, types, problems)
    return value


def substitute(value: Any, env: Mapping[str, Any], where: str, free: Mapping[str, Any]) -> Any:
    """The compiled body with every expression replaced by its value."""
    if isinstance(value, Mapping):
        return {k: substitute(v, env, _path(where, k), free) for k, v in value.items()}
    if isinstance(value, list):
        return [substitute(v, env, _path(where, i), free) for i, v in enumerate(value)]
    if isinstance(value, Expression):
        return evaluated(value, env, where, free)
    return copy.deepcopy(value)
