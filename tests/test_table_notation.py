"""The numbers of the table for people (``--format table``): each column in its own notation.

Issue 21, "numbers a person cannot read": once one value of a table reached about 1e14, every
other column printed 0 (one round-off threshold for the whole table). Here every printed table is
read back and each cell checked against the full-precision value of the same column (the CSV of
the same run, or the array given): a 0 only for a true 0, ``nan`` for NaN, and every other number
equal to the true value rounded to the digits it shows, with at least 4 significant digits (7 for
every value that is not round-off, below 1e-12 of its column's largest magnitude); columns aligned
and the table within the width limit.
"""

from __future__ import annotations

import csv
import io
import math
import re

import numpy as np
import pytest

from _cli_io import run
from linkage.cli.options import TABLE_WIDTH
from linkage.report import format_columns
from linkage.report.tables import table_width

#: below this fraction of its column's largest magnitude a value is round-off (4 digits suffice)
ROUND_OFF = 1e-12

_NUMBER = re.compile(r"^-?(\d+)(?:\.(\d+))?(?:e([+-]\d+))?$")


# ----------------------------------------------------------------------------------------------
# reading a table back
# ----------------------------------------------------------------------------------------------

def table_cells(text: str) -> dict[str, list[str]]:
    """The cells of a table for people by column: the names line, the (skipped) units line, the
    rows; ``#`` lines skipped."""
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    names = lines[0].split()
    rows = [ln.split() for ln in lines[1:] if not ln.lstrip().startswith("[")]
    assert all(len(r) == len(names) for r in rows), "a row with a different number of cells"
    return {name: [r[k] for r in rows] for k, name in enumerate(names)}


def csv_columns(text: str) -> dict[str, list[float]]:
    rows = list(csv.reader(io.StringIO(text)))
    return {name: [float(r[k]) for r in rows[1:]] for k, name in enumerate(rows[0])}


def assert_aligned(text: str, limit: int | None = None) -> None:
    body = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert len({len(ln) for ln in body}) == 1, "lines of different widths"
    assert all(ln == ln.rstrip() for ln in body), "a line ends with a space"
    if limit is not None:
        assert len(body[0]) <= limit


def last_digit(text: str) -> int:
    """Decimal exponent of the last digit a number's text shows (``"0.29"``: -2, ``"1.5e+14"``: 13)."""
    match = _NUMBER.match(text)
    assert match, f"{text!r} is not a number as the table writes them"
    _, decimals, exponent = match.groups()
    return int(exponent or 0) - len(decimals or "")


def assert_cell(text: str, true: float, column_largest: float, where: str) -> None:
    """``text`` is how the table shows ``true``, whose column's largest finite magnitude is
    ``column_largest``."""
    if math.isnan(true):
        assert text == "nan", where
        return
    if math.isinf(true):
        assert text == ("inf" if true > 0 else "-inf"), where
        return
    if true == 0:
        assert text == "0", f"{where}: a true 0 shows as {text!r}"
        return
    shown = float(text)
    assert shown != 0, f"{where}: {true!r} shows as {text!r}"
    assert math.copysign(1.0, shown) == math.copysign(1.0, true), f"{where}: {true!r} shows as {text!r}"
    error = abs(shown - true)
    assert error <= 0.5 * 10.0 ** last_digit(text) * (1 + 1e-9), f"{where}: {true!r} is not {text!r} to its digits"
    assert error <= 5e-4 * abs(true), f"{where}: {true!r} shows as {text!r}: fewer than 4 significant digits"
    if abs(true) >= ROUND_OFF * column_largest:
        assert error <= 5e-7 * abs(true), f"{where}: {true!r} shows as {text!r}: fewer than 7 significant digits"


def assert_table_shows(text: str, columns: dict[str, list[float]]) -> dict[str, list[str]]:
    """Every cell of the table ``text`` against the values of the same column in ``columns``."""
    cells = table_cells(text)
    for name, shown in cells.items():
        values = np.asarray(columns[name], dtype=float)
        finite = np.abs(values[np.isfinite(values)])
        largest = float(finite.max()) if finite.size else 0.0
        assert len(shown) == len(values), name
        for k, (cell, value) in enumerate(zip(shown, values.tolist())):
            assert_cell(cell, value, largest, f"{name} row {k + 1}")
    return cells


# ----------------------------------------------------------------------------------------------
# the formatter on its own
# ----------------------------------------------------------------------------------------------

def test_a_huge_column_does_not_turn_the_others_to_zero():
    # the report: phi, omega, eps, I all printed 0 once a value reached 1e14
    cols = {"i": np.array([1, 2, 3]), "phi_deg": np.array([0.0, 30.0, 60.0]),
            "omega": np.array([-10.17672, -10.29148, -10.34778]),
            "eps": np.array([3.2e14, -2.455896e14, 0.0]),
            "reduced_inertia": np.array([92.17227, 93.58942, np.nan]),
            "balancing_moment": np.array([-2.888758e16, 2.21679e18, 9.56456e17])}
    text = format_columns(cols, "table")
    cells = assert_table_shows(text, {k: v.tolist() for k, v in cols.items()})
    assert cells["phi_deg"] == ["0", "30", "60"]
    assert cells["omega"] == ["-10.17672", "-10.29148", "-10.34778"]
    assert cells["reduced_inertia"] == ["92.17227", "93.58942", "nan"]
    assert cells["eps"][2] == "0" and cells["i"] == ["1", "2", "3"]
    assert_aligned(text)


def test_a_column_mixing_1e14_with_1e_3_and_1e_8_negative_values_zeros_and_nan():
    column = np.array([1.2345678912e14, -1.2345678e-3, 9.87654321e-9, -0.0, 0.0, np.nan, -5.5e14,
                       3.3e-8, -7.654321e2, np.inf, -np.inf])
    text = format_columns({"q": column}, "table")
    cells = assert_table_shows(text, {"q": column.tolist()})["q"]
    assert cells[3] == cells[4] == "0" and cells[5] == "nan"
    numbers = [c for c in cells if _NUMBER.match(c) and c != "0"]
    assert all("e" in c for c in numbers)            # one notation for the whole column: scientific
    assert len({len(c) - c.index("e") for c in numbers}) == 1     # ... its exponents line up
    assert_aligned(text)


def test_an_ordinary_column_reads_as_plain_digits_and_round_off_is_not_zero():
    column = np.array([0.2963995065785367, -0.04748369732417537, 193.99781, -8.673617379884035e-19, 0.0,
                       -0.0002335797, 12.5])
    text = format_columns({"B.x": column}, "table")
    cells = assert_table_shows(text, {"B.x": column.tolist()})["B.x"]
    assert cells == ["0.2963995", "-0.0474837", "193.9978", "-8.674e-19", "0", "-0.0002335797", "12.5"]
    assert_aligned(text)


def test_columns_of_tiny_and_huge_values_alone():
    cols = {"tiny": np.array([7.412485e-11, -3.338625e-12, 0.0]), "huge": np.array([1e300, -2.5e299, 1e288])}
    cells = assert_table_shows(format_columns(cols, "table"), {k: v.tolist() for k, v in cols.items()})
    assert cells["tiny"] == ["7.412485e-11", "-3.338625e-12", "0"]
    assert cells["huge"][0] == "1.000000e+300"


@pytest.mark.parametrize("seed", range(6))
def test_random_columns_read_back_to_their_digits(seed):
    rng = np.random.default_rng(seed)
    cols = {}
    for k in range(12):
        n = 9
        centre, spread = rng.uniform(-250, 250), rng.choice([0.0, 2.0, 8.0, 40.0])
        values = 10.0 ** (centre + spread * rng.uniform(-1, 1, n)) * rng.choice([-1.0, 1.0], n)
        special = rng.uniform(size=n)
        values[special < 0.15] = 0.0
        values[(special >= 0.15) & (special < 0.25)] = np.nan
        cols[f"c{k}"] = values
    cols["k"] = np.arange(9)
    text = format_columns(cols, "table", units={name: "m" for name in cols})
    assert_table_shows(text, {k: v.tolist() for k, v in cols.items()})
    assert_aligned(text)
    assert table_width(cols, {name: "m" for name in cols}) == len(text.splitlines()[0])


def test_csv_and_json_keep_full_precision():
    cols = {"eps": np.array([3.2e14, 1.0 / 3.0]), "phi_deg": np.array([1e-20, 30.0])}
    assert format_columns(cols, "csv").splitlines()[1:] == ["320000000000000.0,1e-20", "0.3333333333333333,30.0"]
    assert format_columns(cols, "json") == '[{"eps": 320000000000000.0, "phi_deg": 1e-20}, ' \
                                           '{"eps": 0.3333333333333333, "phi_deg": 30.0}]'


# ----------------------------------------------------------------------------------------------
# the commands
# ----------------------------------------------------------------------------------------------

# the slider-crank in nanometre-scale lengths: coordinates about 1e-10 m next to angles in rad and deg
TINY = """\
name = "tiny_slider_crank"
input = "1"
output = { quantity = "B.x", start = "max" }

[links.0]
points = { O = [0.0, 0.0] }
guides.slide = { through = [0.0, 1.335e-11], angle_deg = 0 }

[links.1]
line = ["O", "A"]
length = 7.42e-11

[links.2]
line = ["A", "B"]
length = 2.225e-10
points.S2 = { from = "A", distance = 7.41e-11 }

[links.3]
points.B = [0.0, 0.0]

[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"

[assembly.B]
from = "O"
towards_deg = 0
"""


def _fast_scheme(path):
    """The course slider-crank at 1e8 rpm: reactions about 1e15 N and moments 1e14 N m next to
    angles, speeds of 1e7 rad/s and inertias of 90 kg m^2."""
    from conftest import ROOT

    text = (ROOT / "schemes" / "course_slider_crank.toml").read_text()
    assert "mean_speed = -10.472" in text
    path.write_text(text.replace("mean_speed = -10.472", "mean_speed = -1.0472e7")
                    + '\n[checks]\nsilence = ["speed"]\n')
    return path


@pytest.mark.parametrize("command, scheme", [("analyze", "tiny"), ("forces", "fast"), ("dynamics", "fast"),
                                             ("analyze", "slider_crank"), ("forces", "slider_crank"),
                                             ("dynamics", "course_slider_crank")])
def test_the_table_of_a_command_shows_every_csv_value_to_its_digits(capsys, tmp_path, command, scheme):
    if scheme == "tiny":
        (tmp_path / "tiny.toml").write_text(TINY)
        scheme = tmp_path / "tiny.toml"
    elif scheme == "fast":
        scheme = _fast_scheme(tmp_path / "fast.toml")
    code, table, err = run(capsys, command, scheme)
    assert code == 0, err
    code, text, err = run(capsys, command, scheme, "--format", "csv")
    assert code == 0, err
    columns = csv_columns(text)
    cells = assert_table_shows(table, columns)
    assert_aligned(table, TABLE_WIDTH)
    assert len(cells) >= 9                           # the width limit still leaves a full table
    magnitudes = np.abs([v for name in cells for v in columns[name] if math.isfinite(v) and v != 0])
    if str(scheme).endswith("fast.toml"):
        assert magnitudes.max() >= 1e14              # the case of the report
        assert cells["phi_deg"][:3] == ["0", "30", "60"]   # 12 steps of 30 deg, printed 0 before
    if str(scheme).endswith("tiny.toml"):
        assert 1e-11 < np.abs(columns["B.x"]).max() < 1e-9
    for name, shown in cells.items():                # no nonzero value shows as 0
        assert not [v for v, c in zip(columns[name], shown) if c == "0" and v != 0], name
        finite = np.abs([v for v in columns[name] if math.isfinite(v)])
        if finite.size and 1e-4 <= finite.max() < 9.9999995e6:
            # an ordinary column: plain digits for every value that is not round-off, as before
            plain = [c for v, c in zip(columns[name], shown) if 1e-4 <= abs(v) and abs(v) >= ROUND_OFF * finite.max()]
            assert all("e" not in c for c in plain), (name, plain)
