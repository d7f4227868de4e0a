"""The film of one revolution: a GIF whose frames are the drawings of the mechanism at equal steps of
the input, in the declared direction, all at one scale; checked against the kinematics computed
here, against draw_mechanism, and pixel by pixel against the positions of the points."""

import math
import re
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="pictures need the plot extra, which the test extra installs: pip install \".[test]\"")
Image = pytest.importorskip("PIL.Image", reason="pillow comes with matplotlib")

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Polygon

import linkage
from linkage import MechanismBuilder
from linkage.errors import InputError, LinkageError
from linkage.report.animation import (
    Film,
    default_trajectories,
    film_angles,
    write_animation,
)
from linkage.report.plots import PlotExtraMissing, draw_mechanism

SCHEMES = ["four_bar", "slider_crank", "slotted_link_two_dyad"]
#: the named points drawn as black dots (no pair's point) of each scheme
DOTS = {"four_bar": ["E", "S2", "S3"], "slider_crank": ["S2"], "slotted_link_two_dyad": ["C", "S3"]}


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _frames(path) -> list[np.ndarray]:
    """Every frame of a GIF as RGB pixels ``(H, W, 3)``."""
    with Image.open(path) as im:
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB")).copy())
    return out


def _expected_angles(mech, frames, direction=1):
    """Position 1 of the scheme's table (the output's extreme position), then equal steps."""
    phi0 = linkage.extreme_positions(mech).phi_max if mech.output.start == "max" else \
        linkage.extreme_positions(mech).phi_min
    return phi0 + direction * 2 * np.pi * np.arange(frames) / frames


def _drawn(film: Film, k: int) -> dict[str, object]:
    """gid -> artist of what frame k draws over the parts that stay."""
    return {a.get_gid(): a for a in film.draw(k) if a.get_gid()}


def _vertices(artist) -> np.ndarray:
    if isinstance(artist, Line2D):
        return np.asarray(artist.get_xydata(), dtype=float)
    if isinstance(artist, Circle):
        return np.asarray([artist.center], dtype=float)
    if isinstance(artist, Polygon):
        return np.asarray(artist.get_xy(), dtype=float)
    return np.zeros((0, 2))


# -- the GIF ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_gif_has_its_frames_at_its_size_and_the_points_where_the_kinematics_puts_them(name, tmp_path):
    mech = linkage.load(name)
    frames = 12
    path = write_animation(mech, tmp_path / f"{name}.gif", frames=frames, dpi=60)
    with Image.open(path) as im:
        assert im.format == "GIF" and im.n_frames == frames
        size = im.size
        assert im.info["loop"] == 0 and im.info["duration"] == 80     # 12 fps: 1/12 s, in hundredths
    film = Film(mech, frames, dpi=60)
    width, height = film.figure.get_size_inches() * 60
    assert abs(size[0] - width) < 1 and abs(size[1] - height) < 1      # the figure's size at 60 dpi
    assert size[0] <= 6.3 * 60 + 1                                    # the width of an A4 page's text
    pixels = _frames(path)
    for k in range(frames):                                           # every frame differs from every other
        for j in range(k):
            assert np.any(pixels[k] != pixels[j]), (k, j)
    # every dot (a named point at no pair) is black in the GIF where the kinematics puts it
    angles = _expected_angles(mech, frames)
    motion = linkage.analyze(mech, angles)
    to_px = film.ax.transData.transform
    for k in range(frames):
        for point in DOTS[name]:
            x, y = to_px(motion.point(point)[k])
            col, row = round(x - 0.5), round(size[1] - y - 0.5)
            patch = pixels[k][row - 1:row + 2, col - 1:col + 2].astype(int)       # the pixel and its neighbours
            darkest = patch[np.unravel_index(np.argmin(patch.sum(axis=2)), patch.shape[:2])]
            assert np.all(darkest < 60), (name, k, point, darkest)
    film.close()


def test_film_of_72_frames_is_small_and_the_same_byte_for_byte(tmp_path):
    mech = linkage.load("four_bar")
    first = write_animation(mech, tmp_path / "a.gif")
    second = write_animation(mech, tmp_path / "b.gif")
    with Image.open(first) as im:
        assert im.n_frames == 72
        assert im.size[0] >= 400                                     # large enough to read
    assert first.stat().st_size < 2_000_000
    assert first.read_bytes() == second.read_bytes()


def test_frames_of_the_gif_are_the_frames_drawn(tmp_path):
    """The GIF's frame k is the film's figure saved after drawing frame k (one palette: every
    colour of the paper, lines and links exact, antialiased edges to a near colour)."""
    mech = linkage.load("slider_crank")
    path = write_animation(mech, tmp_path / "f.gif", frames=6, dpi=60)
    film = Film(mech, 6, dpi=60)
    for k in (0, 3):
        film.draw(k)
        film.figure.canvas.draw()
        drawn = np.asarray(film.figure.canvas.buffer_rgba())[..., :3].astype(int)
        stored = _frames(path)[k].astype(int)
        differ = np.any(np.abs(drawn - stored) > 40, axis=2)
        assert differ.mean() < 0.002, differ.mean()
        assert np.all(stored[2, 2] == 255)                           # white paper stays white
    film.close()


def test_rendering_after_a_savefig_at_another_resolution_is_unchanged(tmp_path):
    mech = linkage.load("four_bar")
    film, fresh = Film(mech, 6, dpi=60), Film(mech, 6, dpi=60)
    film.render(1)
    film.figure.savefig(tmp_path / "big.png", dpi=120)
    assert np.array_equal(film.render(2), fresh.render(2))
    film.close()
    fresh.close()


# -- each frame is draw_mechanism's drawing --------------------------------------------------------


@pytest.mark.parametrize("name", SCHEMES)
def test_each_frame_draws_what_draw_mechanism_draws_at_that_angle(name):
    mech = linkage.load(name)
    film = Film(mech, 8)
    angles = _expected_angles(mech, 8)
    assert film.angles == pytest.approx(angles, abs=1e-12)
    for k in (0, 5):
        frame = _drawn(film, k)
        single = linkage.analyze(mech, [angles[k]])
        ax = draw_mechanism(single, 0, trajectories=film.trajectories, limits=film.limits)
        theirs = {a.get_gid(): a for a in list(ax.lines) + list(ax.patches) if a.get_gid()}
        moving = {g for g in theirs if g.split(":")[0] in ("link", "link-edge", "slot", "block", "pair", "point")}
        assert moving == {g for g in frame if not g.startswith(("label:", "caption"))}
        for gid in moving:
            mine, other = _vertices(frame[gid]), _vertices(theirs[gid])
            if gid.startswith("block:"):                             # the symbol's size follows the scale
                mine, other = mine[:4].mean(axis=0, keepdims=True), other[:4].mean(axis=0, keepdims=True)
            if gid.startswith("slot:"):                              # a slot's length too: its line is the same
                along = (other[1] - other[0]) / np.hypot(*(other[1] - other[0]))
                off = mine - other[0]
                assert off[:, 0] * along[1] - off[:, 1] * along[0] == pytest.approx([0, 0], abs=1e-12), gid
                continue
            assert mine == pytest.approx(other, abs=1e-12), gid
        for gid, artist in frame.items():                            # pairs and dots where the kinematics says
            kind, _, what = gid.partition(":")
            if kind == "point":
                assert artist.center == pytest.approx(single.point(what)[0], abs=1e-12)
            elif kind == "pair" and not isinstance(mech.pairs[what], linkage.model.mechanism.Prismatic):
                assert artist.center == pytest.approx(single.point(mech.pairs[what].point)[0], abs=1e-12)
        for point in film.trajectories:                              # the trajectories whole, as drawn alone
            mine = next(line for line in film.ax.lines if line.get_gid() == f"trajectory:{point}")
            other = next(line for line in ax.lines if line.get_gid() == f"trajectory:{point}")
            assert mine.get_xydata() == pytest.approx(other.get_xydata(), abs=1e-12)
        supports = [p for p in film.ax.patches if p.get_gid() == "support"]
        assert len(supports) == len([p for p in ax.patches if p.get_gid() == "support"])
        plt.close(ax.figure)
    film.close()


@pytest.mark.parametrize("name", SCHEMES)
def test_every_frame_is_inside_the_same_limits(name):
    film = Film(linkage.load(name), 24)
    x0, x1, y0, y1 = film.limits
    for k in range(len(film)):
        film.draw(k)
        assert film.ax.get_xlim() == (x0, x1) and film.ax.get_ylim() == (y0, y1)
        for artist in list(film.ax.lines) + list(film.ax.patches):
            pts = _vertices(artist)
            if isinstance(artist, Circle):
                pts = np.vstack([pts - artist.radius, pts + artist.radius])
            assert np.all((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1)), \
                (k, artist.get_gid())
        labels = [t for t in film.ax.texts if (t.get_gid() or "").startswith("label:")]
        assert sorted(t.get_text() for t in labels) == sorted(film.scenes[k].points)
    film.close()


def test_captions_give_the_input_angle_and_how_far_it_has_turned():
    mech = linkage.load("four_bar")
    film = Film(mech, 8, trajectories=["E"])
    angles = _expected_angles(mech, 8)
    for k, caption in enumerate(film.captions):
        at = np.degrees(angles[k]) % 360.0
        assert f"φ = {at:.1f}° from the x axis" in caption
        assert f"turned {45.0 * k:.1f}° counter-clockwise from position 1" in caption
        assert "dashed: trajectory of E over a turn" in caption
        assert caption.count("\n") == film.captions[0].count("\n")            # one layout for all frames
        assert max(len(line) for line in caption.splitlines()) <= 62
    film.draw(2)
    assert next(t for t in film.ax.texts if t.get_gid() == "caption").get_text() == film.captions[2]
    film.close()


# -- which angles, which way ----------------------------------------------------------------------


def test_frames_follow_the_declared_direction_of_rotation():
    course = linkage.load("course_slider_crank")                     # mean_speed < 0: clockwise
    spec_start = _expected_angles(course, 1, -1)[0]                 # the slider's far extreme, ~2.58 deg
    assert math.degrees(spec_start) == pytest.approx(2.58, abs=0.01)
    angles = film_angles(course, 36)
    assert np.diff(angles) == pytest.approx(np.full(35, -2 * np.pi / 36))
    assert angles[0] == pytest.approx(spec_start, abs=1e-12)
    film = Film(course, 4)
    assert "turned 90.0° clockwise" in film.captions[1]
    film.close()
    four_bar = linkage.load("four_bar")                              # no [dynamics]: counter-clockwise
    assert np.diff(film_angles(four_bar, 10)) == pytest.approx(np.full(9, 2 * np.pi / 10))


def test_film_of_a_motion_starts_at_its_first_angle_in_its_direction():
    mech = linkage.load("four_bar")
    motion = linkage.analyze(mech, np.radians([100.0, 70.0, 40.0]))
    angles = film_angles(motion, 6)
    assert np.degrees(angles) == pytest.approx(100.0 - 60.0 * np.arange(6))


def test_an_input_range_is_filmed_there_and_back(tmp_path):
    mech = linkage.loads(TANGENT)
    angles = np.degrees(film_angles(mech, 8))
    assert angles == pytest.approx([30, 60, 90, 120, 150, 120, 90, 60])
    film = Film(mech, 8)
    assert "on its way from 30° to 150°" in film.captions[1]
    assert "on its way back from 150° to 30°" in film.captions[5]
    assert "over the input range" in film.captions[0]
    film.close()
    path = write_animation(mech, tmp_path / "tangent.gif", frames=8, dpi=50)
    with Image.open(path) as im:
        assert im.n_frames == 8


# -- refusals -------------------------------------------------------------------------------------


def _short_rocker_four_bar(range_deg=None):
    """O = (0, 0), C = (0.3, 0), OA = 0.1, AB = 0.25, CB = 0.1: it assembles while |AC| <= 0.35,
    i.e. for |phi| <= acos(-0.375) = 112.02 deg."""
    b = MechanismBuilder("short_rocker")
    b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "B"), length=0.25)
    b.link("3", line=("C", "B"), length=0.1)
    for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, a, c)
    b.inputs("1").assembly("B", left_of=("A", "C"))
    if range_deg is not None:
        b.input_range(*np.radians(range_deg))
    return b.build()


def test_refuses_angles_where_the_mechanism_cannot_be_assembled(tmp_path):
    limit = math.degrees(math.acos((0.1**2 + 0.3**2 - 0.35**2) / (2 * 0.1 * 0.3)))
    assert limit == pytest.approx(112.0243, abs=1e-4)
    mech = _short_rocker_four_bar((60.0, 150.0))
    frames = 12                                                       # 60, 75, ... 150, ... 75
    angles = 60 + 90 * np.array([2 * k / frames if 2 * k <= frames else 2 - 2 * k / frames for k in range(frames)])
    bad = sorted({a for a in angles if a > limit})
    with pytest.raises(InputError) as info:
        write_animation(mech, tmp_path / "x.gif", frames=frames)
    message = str(info.value)
    shown = [float(x) for x in re.search(r"phi = ([\d., ]+) deg", message).group(1).split(", ")]
    assert sorted(set(shown)) == pytest.approx(bad)
    assert "short_rocker" in message and "5 of the film's 12" in message
    assert not (tmp_path / "x.gif").exists()
    with pytest.raises(InputError, match=r"cannot be assembled .* over a full turn"):
        Film(_short_rocker_four_bar(), 12)


def test_refuses_bad_requests(tmp_path):
    mech = linkage.load("slider_crank")
    for kwargs, words in [({"frames": 1}, "frames must be a whole number from 2"),
                          ({"frames": 2.5}, "frames must be"), ({"fps": 0}, "fps must be"),
                          ({"dpi": 5}, "dpi must be"), ({"trajectories": ["Q"]}, "no point 'Q'")]:
        with pytest.raises(InputError, match=re.escape(words)):
            write_animation(mech, tmp_path / "x.gif", **kwargs)
    with pytest.raises(InputError, match="no folder"):
        write_animation(mech, tmp_path / "nowhere" / "x.gif")
    with pytest.raises(InputError, match="a Motion or a Mechanism"):
        film_angles("slider_crank")


def test_default_trajectories_are_the_crank_pin_and_the_free_points():
    assert default_trajectories(linkage.load("four_bar")) == ["A", "E"]
    assert default_trajectories(linkage.load("slider_crank")) == ["A"]
    assert default_trajectories(linkage.load("scotch_yoke")) == ["A", "D"]
    assert default_trajectories(linkage.load("six_bar")) == ["A"]


def test_without_matplotlib_the_film_says_what_to_install(monkeypatch, tmp_path):
    mech = linkage.load("four_bar")
    for module in [m for m in list(sys.modules) if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, module, None)
    for call in (lambda: write_animation(mech, tmp_path / "x.gif"), lambda: Film(mech)):
        with pytest.raises(PlotExtraMissing, match=re.escape('pip install "linkage[plot]"')) as info:
            call()
        assert isinstance(info.value, LinkageError)


TANGENT = """
name = "tangent"
input = "1"
output = { quantity = "B.x", start = "max" }
range_deg = [30, 150]

[links.0]
points = { O = [0.0, 0.0] }
guides.rail = { through = [0.0, 0.1], angle_deg = 0 }

[links.1]
points = { O = [0.0, 0.0] }
guides.slot = { through = "O", angle_deg = 0 }

[links.2]
points = { B = [0.0, 0.0] }

[links.3]
points = { B = [0.0, 0.0] }

[pairs.O]
links = ["0", "1"]
[pairs.slot]
kind = "P"
links = ["1", "2"]
guide = "slot"
at = "B"
[pairs.B]
links = ["2", "3"]
[pairs.rail]
kind = "P"
links = ["0", "3"]
guide = "rail"
at = "B"
"""
