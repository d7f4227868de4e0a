"""Format a table of equal-length columns as aligned text, CSV or JSON; units and selection of
columns.

A table is an ordered mapping ``name -> 1-D array`` (for analysis results the first columns are
``i``, the position number, and ``phi_deg``). Every command that prints a table (analyze, forces,
dynamics ...) goes through :func:`format_columns`, so the three formats look the same everywhere:

- ``table``: aligned, right-justified text for people; with ``units``, a second header line gives
  each column's unit in brackets. Each float column has its own notation (:func:`column_cells`):
  plain numbers to 7 significant digits (``0.2963995``, ``-172.3759``) when its largest magnitude
  is between 1e-4 and 1e7, else scientific notation to 7 significant digits (``1.234568e+14``).
  Only a true 0 prints as ``0``; a value below 1e-12 of its column's largest (round-off, e.g. at a
  dead centre) prints with 4 (``-8.674e-19``); a missing value prints ``nan``;
- ``csv``: one header row, numbers at full precision (``repr``, round-trips exactly), ``nan``
  where a value is missing;
- ``json``: a list of row objects ``{column: value}``; with ``meta``, an object
  ``{**meta, "rows": [...]}`` (with ``units``, also ``"units": {column: unit}``). Missing values
  (NaN, infinities) are written as ``null``.

The unit of a column follows from its name (:func:`column_unit`), and a selection of columns
from a list of names and shell-style patterns (:func:`select_columns`).

>>> import numpy as np
>>> cols = {"phi_deg": np.array([0.0, 180.0]), "B.x": np.array([0.29, np.nan])}
>>> print(format_columns(cols, "table"), end="")
phi_deg   B.x
      0  0.29
    180   nan
>>> print(format_columns(cols, "table", units=units_of(cols)), end="")
phi_deg   B.x
  [deg]   [m]
      0  0.29
    180   nan
>>> format_columns(cols, "json", meta={"scheme": "demo"})
'{"scheme": "demo", "rows": [{"phi_deg": 0.0, "B.x": 0.29}, {"phi_deg": 180.0, "B.x": null}]}'
"""

from __future__ import annotations

import csv
import fnmatch
import io
import json
import math
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ..errors import InputError

__all__ = ["FORMATS", "format_columns", "column_unit", "units_of", "select_columns", "table_width", "per_turned_angle",
           "column_cells"]

#: the output formats understood by :func:`format_columns`
FORMATS = ("table", "csv", "json")

#: significant digits of numbers in the human-readable table
TABLE_DIGITS = 7

#: values smaller than this fraction of the largest magnitude of their column are round-off around
#: zero: the table for people shows them with :data:`ROUND_OFF_DIGITS` (never as 0); the answer key
#: (:mod:`linkage.course.key`) writes them as 0
TABLE_ZERO = 1e-12

#: significant digits of a round-off value in the human-readable table
ROUND_OFF_DIGITS = 4

#: a float column whose largest magnitude (to :data:`TABLE_DIGITS`) has a decimal exponent in
#: this range is written in plain digits (as ``format(x, ".7g")``), any other in scientific notation
PLAIN_EXPONENTS = range(-4, TABLE_DIGITS)


def format_columns(columns: Mapping[str, Any], fmt: str = "table",
                   meta: Mapping[str, Any] | None = None,
                   units: Mapping[str, str | None] | None = None) -> str:
    """Text of a table of equal-length columns in the format ``fmt``.

    Parameters
    ----------
    columns : mapping of str -> array_like, shape (N,)
        The columns in order (numbers; integer and boolean columns keep their type).
    fmt : {"table", "csv", "json"}
    meta : mapping, optional
        Data about the table (scheme name, settings ...), JSON-serialisable values. ``json``:
        the result is ``{**meta, "rows": [...]}`` instead of a bare list of rows; ``table``: one
        ``# key: value`` line per entry above the table; ``csv``: not written (pure data).
    units : mapping of str -> str or None, optional
        Unit of each column (e.g. from :func:`units_of`; None or missing: no unit). ``table``: a
        second header line ``[unit]``; ``json`` with ``meta``: a ``"units"`` entry; ``csv``: not
        written (the header is the names only, as ``--columns`` takes them).

    Returns
    -------
    str
        The text, ending with a newline (except ``json``, one line without a newline).
    """
    if fmt not in FORMATS:
        raise InputError(f"unknown table format {fmt!r}: expected one of {', '.join(FORMATS)}")
    cols = _check(columns)
    if fmt == "csv":
        return _csv(cols)
    units = {k: v for k, v in (units or {}).items() if k in cols and v}
    if fmt == "json":
        if meta is not None and units:
            meta = {**meta, "units": units}
        return _json(cols, meta)
    return _table(cols, meta, units)


def _check(columns: Mapping[str, Any]) -> dict[str, np.ndarray]:
    if not columns:
        raise InputError("a table needs at least one column")
    cols = {str(k): np.asarray(v) for k, v in columns.items()}
    bad = [k for k, v in cols.items() if v.ndim != 1]
    if bad:
        raise InputError(f"table columns must be 1-D arrays: {bad} are not")
    lengths = {k: len(v) for k, v in cols.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"table columns must have equal lengths, got {lengths}")
    return cols


def _values(column: np.ndarray) -> list:
    """Python scalars of a column (int, bool, float or str)."""
    return column.tolist()


def _exact(x: Any) -> str:
    if isinstance(x, float):
        return repr(x)  # shortest text that reads back to the same float; 'nan', 'inf'
    return str(x)


def _csv(cols: dict[str, np.ndarray]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(cols)
    values = [_values(c) for c in cols.values()]
    for row in zip(*values):
        writer.writerow([_exact(x) for x in row])
    return out.getvalue()


def _json_value(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _plain(x: Any) -> Any:
    """``meta`` values made JSON-serialisable (numpy scalars and arrays, tuples)."""
    if isinstance(x, np.ndarray):
        return [_plain(v) for v in x.tolist()]
    if isinstance(x, np.generic):
        return _json_value(x.item())
    if isinstance(x, Mapping):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    return _json_value(x)


def _json(cols: dict[str, np.ndarray], meta: Mapping[str, Any] | None) -> str:
    names = list(cols)
    values = [_values(c) for c in cols.values()]
    rows = [{n: _json_value(x) for n, x in zip(names, row)} for row in zip(*values)]
    doc: Any = rows if meta is None else {**_plain(dict(meta)), "rows": rows}
    return json.dumps(doc, ensure_ascii=False, allow_nan=False)


def column_cells(column: Any) -> list[str]:
    """The texts of one column's values in the table for people, in its own notation.

    A float column is written in plain digits to :data:`TABLE_DIGITS` significant digits when its
    largest finite magnitude is between 1e-4 and 1e7 (``format(x, ".7g")``: a smaller value of it
    takes an exponent), else in scientific notation to :data:`TABLE_DIGITS` significant digits for
    every value, so that its exponents line up. A value below :data:`TABLE_ZERO` of the column's
    largest magnitude is round-off: it is shown in scientific notation to :data:`ROUND_OFF_DIGITS`
    significant digits. Only a value equal to 0 is shown as ``0``; NaN as ``nan``, infinities as
    ``inf``, ``-inf``. Integer, boolean and text columns are shown as they are.

    Parameters
    ----------
    column : array_like, shape (N,)

    Returns
    -------
    list of str, length N

    >>> column_cells([0.29, -0.0, float("nan"), 3e-19])
    ['0.29', '0', 'nan', '3.000e-19']
    >>> column_cells([2.5e14, -1500.0, 1e-3])
    ['2.500000e+14', '-1.500000e+03', '1.000e-03']
    """
    column = np.asarray(column)
    if column.dtype.kind != "f":
        return [str(x) for x in _values(column)]
    magnitudes = np.abs(column[np.isfinite(column)])
    largest = float(magnitudes.max()) if magnitudes.size else 0.0
    plain = largest == 0.0 or _exponent(largest) in PLAIN_EXPONENTS
    return [_cell(x, largest, plain) for x in _values(column)]


def _exponent(x: float) -> int:
    """Decimal exponent of ``x != 0`` once rounded to :data:`TABLE_DIGITS` significant digits."""
    return int(f"{x:.{TABLE_DIGITS - 1}e}".partition("e")[2])


def _cell(x: float, largest: float, plain: bool) -> str:
    if x == 0.0 or not math.isfinite(x):
        return f"{x + 0.0:g}"                                  # 0 (+ 0.0: no "-0"), nan, inf, -inf
    if abs(x) < TABLE_ZERO * largest:
        return f"{x:.{ROUND_OFF_DIGITS - 1}e}"
    return f"{x:.{TABLE_DIGITS}g}" if plain else f"{x:.{TABLE_DIGITS - 1}e}"


def _table(cols: dict[str, np.ndarray], meta: Mapping[str, Any] | None,
           units: Mapping[str, str] | None = None) -> str:
    cells = {name: column_cells(c) for name, c in cols.items()}
    heads = {name: f"[{units[name]}]" if units and units.get(name) else "" for name in cols}
    widths = {name: max([len(name), len(heads[name])] + [len(s) for s in cells[name]]) for name in cols}
    lines = [f"# {k}: {v}" for k, v in (meta or {}).items()]
    lines.append("  ".join(name.rjust(widths[name]) for name in cols))
    if any(heads.values()):
        lines.append("  ".join(heads[name].rjust(widths[name]) for name in cols))
    for row in zip(*cells.values()):
        lines.append("  ".join(s.rjust(widths[name]) for name, s in zip(cols, row)))
    return "\n".join(lines) + "\n"


def table_width(columns: Mapping[str, Any], units: Mapping[str, str | None] | None = None) -> int:
    """Width in characters of the widest line of ``format_columns(columns, "table", units=units)``
    (without metadata lines)."""
    text = format_columns(columns, "table", units=units)
    return max(len(line) for line in text.splitlines())


# ----------------------------------------------------------------------------------------------
# units of the columns
# ----------------------------------------------------------------------------------------------

#: units of whole column names
_NAMED_UNITS = {
    "t": "s",
    "balancing_moment": "N m",
    "reduced_moment_resistance": "N m",
    "reduced_moment_driving": "N m",
    "reduced_inertia": "kg m^2",
    "reduced_inertia_derivative": "kg m^2/rad",
    "omega": "rad/s",
    "eps": "rad/s^2",
    "v": "m/s",
    "a": "m/s^2",
    "force": "N",
    "reduced_force": "N",
    "power_lost": "W",
    "reduced_moment_friction": "N m",
    "reduced_mass": "kg",
}

#: units of ``<object>.<quantity>`` columns by quantity, for the value, ``'`` and ``''``
_QUANTITY_UNITS = {
    "x": ("m", "m/rad", "m/rad^2"),        # point coordinates and their analogs
    "y": ("m", "m/rad", "m/rad^2"),
    "s": ("m", "m/rad", "m/rad^2"),        # slide of a prismatic pair
    "theta": ("rad", "rad/rad", "rad/rad^2"),  # link angle and its analogs
    "R": ("N",), "Rx": ("N",), "Ry": ("N",),  # pair reaction: magnitude, components
    "M": ("N m",),                         # moment in a prismatic pair
    "Mf": ("N m",), "Ff": ("N",),          # friction moment (revolute pair) and force (prismatic pair)
    "power_lost": ("W",),                  # power friction takes in a pair
}


def per_turned_angle(columns: Mapping[str, Any], direction: int) -> dict[str, Any]:
    """The columns with their analogs taken with respect to the angle turned, for people.

    Tables, keys, diagrams and sheets run over psi, the input angle turned from position 1 in the
    direction of rotation (``direction``: +1 counter-clockwise, -1 clockwise; +1 for a slide
    input), so that a curve and its derivative agree by graphical differentiation whatever the
    sense. With ``phi = phi_1 + direction * psi``: ``dq/dpsi = direction * dq/dphi`` and
    ``d2q/dpsi2 = d2q/dphi2``. The first analogs (names ending in exactly one ``'``) are
    multiplied by ``direction``; every other column is kept as it is (the Python API's
    :class:`~linkage.kinematics.motion.Motion` keeps d/dphi).

    >>> import numpy as np
    >>> per_turned_angle({"B.x": np.array([0.3]), "B.x'": np.array([0.1]), "B.x''": np.array([-2.0])}, -1)
    {'B.x': array([0.3]), "B.x'": array([-0.1]), "B.x''": array([-2.])}
    """
    if direction not in (1, -1):
        raise ValueError(f"direction must be +1 or -1, got {direction!r}")
    return {name: (direction * np.asarray(values) if name.endswith("'") and not name.endswith("''") else values)
            for name, values in columns.items()}


def column_unit(name: str, per: str = "rad") -> str | None:
    """The unit of a table column, from its name (None: a count or a pure number). ``per``: the
    unit of the first input's coordinate, which the analogs are per (``"m"`` for a slide input:
    ``B.x'`` m/m, ``3.theta''`` rad/m^2, and the position column ``s`` is in m).

    ``i`` none; ``*_deg`` deg; ``P.x P.y K.s`` m (with ``'`` m/rad, ``''`` m/rad^2);
    ``L.theta`` rad (rad/rad, rad/rad^2); ``K.R K.Rx K.Ry`` N; ``K.M`` N m; ``balancing_moment``
    and ``balancing_moment.L``, ``reduced_moment_*`` N m; ``reduced_inertia`` kg m^2; ``reduced_inertia_derivative``
    kg m^2/rad; ``omega`` rad/s; ``eps`` rad/s^2; ``t`` s.

    >>> [column_unit(n) for n in ("i", "phi_deg", "B.x'", "3.theta''", "A.R", "omega")]
    [None, 'deg', 'm/rad', 'rad/rad^2', 'N', 'rad/s']
    """
    if name.endswith("_deg"):
        return "deg"
    if name == "s" and per == "m":
        return "m"
    if name in _NAMED_UNITS:
        return _NAMED_UNITS[name]
    if name.startswith("balancing_moment."):      # a further input link's balancing moment
        return "N m"
    if name.startswith("balancing_force"):        # the balancing force of a slide input
        return "N"
    _, dot, quantity = name.rpartition(".")
    if not dot:
        return None
    base = quantity.rstrip("'")
    order = len(quantity) - len(base)
    units = _QUANTITY_UNITS.get(base, ())
    unit = units[order] if order < len(units) else None
    return unit.replace("/rad", f"/{per}") if unit and order else unit


def units_of(columns: Iterable[str]) -> dict[str, str | None]:
    """``{name: column_unit(name, per)}`` for the given column names; a table whose position column
    is a slide ``s`` (m, a slide input) has its analogs per m."""
    columns = list(columns)
    per = "m" if "s" in columns else "rad"
    return {name: column_unit(name, per) for name in columns}


# ----------------------------------------------------------------------------------------------
# selection of columns
# ----------------------------------------------------------------------------------------------

_WILDCARDS = set("*?[")


def select_columns(columns: Mapping[str, Any], request: str | Sequence[str],
                   always: Sequence[str] = ("i", "phi_deg")) -> dict[str, Any]:
    """The columns a request names, in its order, after the ``always`` columns.

    Parameters
    ----------
    columns : mapping of str -> array
        Every column available.
    request : str or sequence of str
        Column names and shell-style patterns (``*``, ``?``, ``[seq]``; case-sensitive), as a
        comma-separated string (``"B.*,3.theta"``) or a sequence. A pattern contributes its
        matches in table order; a column already taken is not repeated.
    always : sequence of str
        Columns that lead every selection when the table has them (the position number and the
        input angle).

    Raises
    ------
    InputError
        (a ``ValueError``) An empty request, or an entry that names no column (an unknown name, or
        a pattern that matches nothing): the message names every such entry and lists the
        available columns.

    >>> cols = dict.fromkeys(["i", "phi_deg", "B.x", "B.y", "B.x'", "3.theta"], [0.0])
    >>> list(select_columns(cols, "B.*,3.theta"))
    ['i', 'phi_deg', 'B.x', 'B.y', "B.x'", '3.theta']
    """
    items = [r.strip() for r in (request.split(",") if isinstance(request, str) else request)]
    items = [r for r in items if r]
    if not items:
        raise InputError(f"no column named: give names or patterns separated by commas; the columns are: "
                         f"{', '.join(columns)}")
    chosen = [name for name in always if name in columns]
    missing = []
    for item in items:
        if _WILDCARDS & set(item):
            matches = [name for name in columns if fnmatch.fnmatchcase(name, item)]
        else:
            matches = [item] if item in columns else []
        if not matches:
            missing.append(item)
        chosen += [m for m in matches if m not in chosen]
    if missing:
        what = "; ".join(f"pattern {m!r} matches no column" if _WILDCARDS & set(m) else f"unknown column {m!r}"
                         for m in missing)
        raise InputError(f"{what}; the columns are: {', '.join(columns)}")
    return {name: columns[name] for name in chosen}
