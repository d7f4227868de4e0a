"""The friction picture and ``linkage report --friction`` (issue 23: friction).

- the report with ``--friction`` writes friction.png/svg and friction.csv, and the page shows them;
- without a [friction] section the option is refused with one line naming the section, before
  anything is written;
- examples/friction.py runs and writes its picture;
- the picture draws what the analysis computed: its η at the table positions is the efficiency
  of the test's own powers (the slider's resistance times its velocity, the balancing moment
  times ω), its total the sum of the pairs' lines, its dashed line the cycle's efficiency.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib", reason="pictures need the plot extra (matplotlib)")

import linkage  # noqa: E402
from linkage.errors import InputError  # noqa: E402
from linkage.kinetostatics.efficiency import cycle_works  # noqa: E402
from linkage.kinetostatics.reactions import solve_reactions  # noqa: E402
from linkage.report.friction_plots import plot_friction  # noqa: E402

from _cli_io import read_csv  # noqa: E402

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parent.parent
OMEGA = -10.472   # rad/s, the press's mean speed (clockwise)
#: the press's useful resistance on the slider along x at positions 1..13, N (its scheme file)
RESISTANCE = np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -12321, -27142, -125000], float)


@pytest.fixture(scope="module")
def press():
    """The press at its 13 table positions (from the slider's far extreme, clockwise) at the mean
    speed, with the friction of its scheme; and its picture."""
    mech = linkage.load("course_slider_crank")
    motion = linkage.analyze(mech, linkage.table_angles(mech, 12, direction=-1), order=2, omega=OMEGA, eps=0.0)
    ends = np.zeros(13, bool)
    ends[-1] = True
    reactions = solve_reactions(motion, ends=ends, friction=True)
    fig = plot_friction(reactions)
    yield mech, motion, reactions, fig
    matplotlib.pyplot.close(fig)


def _line(fig, gid: str):
    found = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == gid]
    assert len(found) == 1, (gid, [ln.get_gid() for ax in fig.axes for ln in ax.get_lines()])
    return np.asarray(found[0].get_xdata(), float), np.asarray(found[0].get_ydata(), float)


def test_the_plotted_efficiency_is_useful_over_driving_power_at_the_table_positions(press):
    """η = −P_useful / P_driving with the test's own powers: P_useful = F_x·v_Bx (the slider's
    resistance times its velocity, v_Bx = x_B'·ω; B is the slider's origin), P_driving = M_b·ω;
    left out (NaN) where the drive delivers no power."""
    _, motion, reactions, fig = press
    x, eta = _line(fig, "positions:efficiency")
    assert np.array_equal(x, 30.0 * np.arange(13))    # deg turned from position 1, clockwise
    useful = RESISTANCE * motion.first["3"][:, 0] * OMEGA
    driving = reactions.balancing_moment * OMEGA
    expected = np.where(driving > 0, -useful / np.where(driving > 0, driving, 1.0), np.nan)
    assert np.isnan(expected).any() and np.isfinite(expected).sum() >= 8   # both kinds of position are drawn
    np.testing.assert_allclose(eta, expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(np.isnan(eta), np.isnan(reactions.efficiency()))
    np.testing.assert_allclose(eta, reactions.efficiency(), rtol=1e-12, atol=1e-14)


def test_the_fine_curves_pass_through_the_table_positions(press):
    _, _, reactions, fig = press
    for name in ("efficiency", "power_lost"):
        fx, fy = _line(fig, f"curve:{name}")
        x, y = _line(fig, f"positions:{name}")
        assert len(fx) > 10 * len(x)
        at = np.searchsorted(fx, x)
        np.testing.assert_allclose(fx[at], x, atol=1e-9)
        np.testing.assert_allclose(fy[at], y, rtol=1e-9, atol=1e-9)


def test_the_plotted_total_is_the_sum_of_the_pairs_lines(press):
    _, _, reactions, fig = press
    pairs = sorted(reactions.friction.pairs)
    assert pairs == ["A", "B", "O", "slide"]
    for kind in ("positions", "curve"):
        x, total = _line(fig, f"{kind}:power_lost")
        each = [_line(fig, f"{kind}:{p}.power_lost")[1] for p in pairs]
        np.testing.assert_allclose(total, np.sum(each, axis=0), rtol=1e-12, atol=1e-9)
        assert np.all(np.array(each) >= -1e-9)     # a loss, W
        assert total.max() > 1000.0                 # the press loses kW near the end of its stroke


def test_the_revolute_pairs_lines_are_friction_moment_times_relative_speed(press):
    """Pair A joins the crank 1 and the rod 2: its loss is |M_f|·|ω1 − ω2| with M_f = f·r·|R_A|
    (f = 0.08, r = 0.03 m in the scheme), ω_k = θ_k'·ω."""
    _, motion, reactions, fig = press
    _, lost = _line(fig, "positions:A.power_lost")
    relative = (motion.first["1"][:, 2] - motion.first["2"][:, 2]) * OMEGA
    np.testing.assert_allclose(lost, 0.08 * 0.03 * reactions.magnitude("A") * np.abs(relative), rtol=1e-9)


def test_the_dashed_line_is_the_cycle_efficiency(press):
    mech, _, _, fig = press
    works = cycle_works(mech, OMEGA)
    _, y = _line(fig, "cycle-efficiency")
    assert np.allclose(y, works.efficiency, rtol=0, atol=1e-15)
    assert works.efficiency == pytest.approx(works.useful / works.driving, rel=1e-15)
    assert works.driving == pytest.approx(works.useful + works.friction, rel=1e-9)  # a turn: the rest returns
    texts = [t.get_text() for t in fig.legends[0].get_texts()] if fig.legends else \
        [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    assert any(f"{works.efficiency:.4f}" in t for t in texts), texts


def test_the_picture_names_its_units_scheme_and_speed(press):
    _, _, _, fig = press
    losses, eta = fig.axes[0], fig.axes[1]
    assert losses.get_ylabel().endswith(", W")
    assert "dimensionless" in eta.get_ylabel()
    assert eta.get_xlabel().endswith(", deg")
    assert "course_slider_crank" in fig.get_suptitle() and "10.472 rad/s" in fig.get_suptitle()
    assert "no power" in fig.get_supxlabel()    # why η has gaps


def test_a_picture_needs_friction(press):
    _, motion, _, _ = press
    with pytest.raises(InputError, match="friction"):
        plot_friction(solve_reactions(motion))


# ----------------------------------------------------------------------------------------------
# linkage report --friction, the example
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report(linkage_run):
    pytest.importorskip("jinja2", reason="the report needs the report extra (Jinja2)")
    pytest.importorskip("tqdm", reason="the report needs the report extra (tqdm)")
    done = linkage_run("report", "course_slider_crank", "--out", "report", "--friction")
    assert done.status == 0, done.err
    return done.cwd / "report"


def test_the_report_with_friction_writes_the_picture_and_the_table(report):
    from PIL import Image

    with Image.open(report / "friction.png") as image:
        width, height = image.size
    assert 700 <= width <= 1800 and 300 <= height <= 2600
    assert (report / "friction.svg").read_text(encoding="utf-8").lstrip().startswith("<?xml")
    page = (report / "index.html").read_text(encoding="utf-8")
    assert 'src="friction.png"' in page and 'href="friction.csv"' in page
    table = read_csv((report / "friction.csv").read_text(encoding="utf-8"))
    pairs = [k[: -len(".power_lost")] for k in table if k.endswith(".power_lost")]
    assert sorted(pairs) == ["A", "B", "O", "slide"]
    np.testing.assert_allclose(table["power_lost"], sum(table[f"{p}.power_lost"] for p in pairs), rtol=1e-12)
    assert "slide.Ff" in table and "A.Mf" in table and "efficiency" in table
    forces = read_csv((report / "forces.csv").read_text(encoding="utf-8"))
    np.testing.assert_allclose(forces["balancing_moment"], table["balancing_moment"], rtol=0)


def test_the_report_with_friction_carries_it_into_the_dynamics(report):
    summary = json.loads((report / "dynamics.json").read_text(encoding="utf-8"))
    text = json.dumps(summary)
    assert "friction_work" in text and "cycle_efficiency" in text
    cycle = json.loads((report / "forces.json").read_text(encoding="utf-8"))["cycle"]
    assert cycle["driving_work"] == pytest.approx(cycle["useful_work"] + cycle["friction_work"], rel=1e-9)
    assert math.isclose(cycle["efficiency"], cycle["useful_work"] / cycle["driving_work"], rel_tol=1e-12)


def test_report_friction_without_a_friction_section_is_one_line(linkage_run):
    done = linkage_run("report", "four_bar", "--out", "report", "--friction")
    assert done.status == 2
    lines = done.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("linkage: error:"), done.err
    assert "[friction]" in lines[0] and "four_bar" in lines[0] and "Traceback" not in done.err
    assert not (done.cwd / "report").exists()     # refused before anything is written


def test_the_friction_example_runs(example_run):
    done = example_run(ROOT / "examples" / "friction.py")
    assert done.status == 0, done.err
    assert (done.cwd / "friction.png").stat().st_size > 10_000
    line = next(ln for ln in done.out.splitlines() if ln.startswith("one turn"))
    efficiency = float(line.rsplit(" ", 1)[1])
    works = cycle_works(linkage.load("course_slider_crank"), OMEGA)
    assert efficiency == pytest.approx(works.efficiency, abs=5e-5)
