"""The runnable examples run, and the plots draw what the analysis computed."""

from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="pictures need the plot extra, which the test extra installs: pip install \".[test]\"")

import linkage  # noqa: E402 (after the skip when matplotlib is missing)
from linkage.report.plots import draw_mechanism, plot_columns  # noqa: E402

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 2


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_writes_its_pictures(script, example_run):
    done = example_run(script)
    assert done.status == 0, done.err
    assert "Traceback" not in done.err
    assert list(done.cwd.rglob("*.png")), done.out


def test_custom_mechanism_example_reports_the_lever_stroke(example_run):
    """The lever press: a crank of 0.06 m at 0.15 m from the lever pivot swings the 0.4 m lever by
    +-asin(0.06/0.15); the rod keeps the slider on the rail y = 0.45, so the stroke of F is the
    difference of x_F = x_D + sqrt(0.2^2 - (0.45 - y_D)^2) at the two lever extremes."""
    out = example_run(ROOT / "examples" / "custom_mechanism.py").out
    swing = np.arcsin(0.06 / 0.15)
    x_f = [0.4 * np.sin(s) + np.sqrt(0.2**2 - (0.45 - 0.4 * np.cos(s)) ** 2) for s in (swing, -swing)]
    stroke_mm = (x_f[0] - x_f[1]) * 1000
    line = next(ln for ln in out.splitlines() if ln.startswith("stroke of F"))
    assert float(line.split()[3]) == pytest.approx(stroke_mm, abs=0.01)


@pytest.mark.parametrize("name", list(linkage.shipped_schemes()))
def test_draw_mechanism_puts_every_pair_where_the_analysis_has_it(name):
    """A revolute pair is a circle at its point, a prismatic pair the slider's block centred there (or,
    for a hydraulic cylinder, the rod's end there and its piston inside the barrel)."""
    mech = linkage.load(name)
    # a crank at 40 deg; a slide input 40 % into its stroke
    at = np.radians([40.0]) if mech.coordinate.is_angle else [np.dot([0.6, 0.4], mech.input_range)]
    motion = linkage.analyze(mech, at)
    ax = draw_mechanism(motion, 0)
    artists = {p.get_gid(): p for p in [*ax.patches, *ax.lines] if p.get_gid()}
    for pair in mech.pairs.values():
        expected = motion.point(pair.point)[0]
        if pair.kind == "R":
            centre = np.asarray(artists[f"pair:{pair.name}"].center)
        elif f"block:{pair.links[1]}" in artists:
            centre = artists[f"block:{pair.links[1]}"].get_xy()[:4].mean(axis=0)
        else:   # a hydraulic cylinder: the rod's outer end at the pair's point, its piston in the barrel
            rod = np.column_stack(artists[f"rod:{pair.links[1]}"].get_data())
            centre = rod[np.argmin(np.hypot(*(rod - expected).T))]
            barrel = artists[f"barrel:{pair.links[0]}"].get_path()
            piston = np.column_stack(artists[f"piston:{pair.links[1]}"].get_data()).mean(axis=0)
            assert barrel.contains_point(piston), pair.name
        assert np.hypot(*(centre - expected)) < 1e-12 * mech.size, pair.name
    matplotlib.pyplot.close(ax.figure)


def test_plot_columns_plots_the_columns_and_names_a_missing_one():
    motion = linkage.analyze(linkage.load("four_bar"), np.radians(np.arange(0, 361, 30.0)))
    cols = motion.columns()
    ax = plot_columns(cols, ["3.theta'"])
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), cols["3.theta'"])
    with pytest.raises(ValueError, match="no column 'nope'"):
        plot_columns(cols, ["nope"])
    matplotlib.pyplot.close("all")
