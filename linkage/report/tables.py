"""Format a table of equal-length columns as aligned text, CSV or JSON.

A table is an ordered mapping ``name -> 1-D array`` (for analysis results the first column is
``phi_deg``). Every command that prints a table (analyze, forces, dynamics ...) goes through
:func:`format_columns`, so the three formats look the same everywhere:

- ``table``: aligned, right-justified text for people, numbers to 7 significant digits;
- ``csv``: one header row, numbers at full precision (``repr``, round-trips exactly), ``nan``
  where a value is missing;
- ``json``: a list of row objects ``{column: value}``; with ``meta``, an object
  ``{**meta, "rows": [...]}``. Missing values (NaN, infinities) are written as ``null``.

>>> import numpy as np
>>> cols = {"phi_deg": np.array([0.0, 180.0]), "B.x": np.array([0.29, np.nan])}
>>> print(format_columns(cols, "table"), end="")
phi_deg   B.x
      0  0.29
    180   nan
>>> format_columns(cols, "json", meta={"scheme": "demo"})
'{"scheme": "demo", "rows": [{"phi_deg": 0.0, "B.x": 0.29}, {"phi_deg": 180.0, "B.x": null}]}'
"""

from __future__ import annotations

import csv
import io
import json
import math
from typing import Any, Mapping

import numpy as np

from ..errors import InputError

__all__ = ["FORMATS", "format_columns"]

#: the output formats understood by :func:`format_columns`
FORMATS = ("table", "csv", "json")

#: significant digits of numbers in the human-readable table
TABLE_DIGITS = 7

#: in the human-readable table, values smaller than this fraction of the table's largest
#: magnitude are round-off noise around zero and are shown as 0 (CSV and JSON keep them)
TABLE_ZERO = 1e-12


def format_columns(columns: Mapping[str, Any], fmt: str = "table",
                   meta: Mapping[str, Any] | None = None) -> str:
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
    if fmt == "json":
        return _json(cols, meta)
    return _table(cols, meta)


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


def _human(column: np.ndarray, scale: float) -> list[str]:
    if column.dtype.kind != "f":
        return [str(x) for x in _values(column)]
    cleaned = np.where(np.abs(column) <= TABLE_ZERO * scale, 0.0, column)
    return [f"{x:.{TABLE_DIGITS}g}" for x in (cleaned + 0.0).tolist()]  # + 0.0: no "-0"


def _scale(cols: dict[str, np.ndarray]) -> float:
    """Largest finite magnitude of the table's float columns."""
    finite = [np.abs(c[np.isfinite(c)]) for c in cols.values() if c.dtype.kind == "f"]
    finite = [f for f in finite if f.size]
    return float(max(f.max() for f in finite)) if finite else 0.0


def _table(cols: dict[str, np.ndarray], meta: Mapping[str, Any] | None) -> str:
    scale = _scale(cols)
    cells = {name: _human(c, scale) for name, c in cols.items()}
    widths = {name: max([len(name)] + [len(s) for s in cells[name]]) for name in cols}
    lines = [f"# {k}: {v}" for k, v in (meta or {}).items()]
    lines.append("  ".join(name.rjust(widths[name]) for name in cols))
    for row in zip(*cells.values()):
        lines.append("  ".join(s.rjust(widths[name]) for name, s in zip(cols, row)))
    return "\n".join(lines) + "\n"
