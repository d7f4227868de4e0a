"""The film of one revolution: the mechanism drawn to scale at equal steps of the input, as a GIF.

Each frame is the drawing of :func:`~linkage.report.plots.draw_mechanism` (links, pairs, sliders,
hatched frame pivots and guides, labels placed clear of everything), with one scale, one set of
axis limits and one placement of the frame's supports for the whole film, so that nothing jumps
between frames and nothing is cut off. The trajectories of the chosen points are drawn whole in
every frame, the points themselves where they are at that frame. The caption of each frame gives
the input angle.

- :func:`film_angles` -- the input angles of the frames;
- :class:`Film` -- the figure and the drawing of each frame (for a look at one frame, or a test);
- :func:`write_animation` -- the GIF (``matplotlib.animation.PillowWriter``: Pillow, which
  matplotlib itself needs; no other library).

The frames follow the direction of rotation the scheme declares (the sign of ``[dynamics]
mean_speed``, else counter-clockwise) from position 1 of its tables (the output's extreme
position, or ``[dynamics] start_deg``); a mechanism with an input range goes from the range's
first end to its other end and back. Needs the ``plot`` extra (matplotlib).

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import linkage
>>> film = Film(linkage.load("four_bar"), frames=8)
>>> [round(float(a), 2) for a in np.degrees(film.angles[:3])]
[235.77, 280.77, 325.77]
>>> film.close()
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from assur.base import CANNOT_ASSEMBLE

from ..errors import InputError
from ..kinematics.extremes import table_angles
from ..kinematics.motion import Motion, analyze
from ..model.mechanism import Mechanism
from ..model.scheme import section_of
from .drawing import (
    PIN,
    SUPPORT_DIRECTIONS,
    Geometry,
    Scene,
    add_artists,
    convex_hull,
    draw_scene,
    drawing_limits,
    figure_for,
    moving_artists,
    place_point_labels,
    scene_obstacles,
    scene_samples,
    support,
)
from .labels import points_inside
from .style import FONT, pyplot
from .words import CAPTION_CHARS, plain, trajectory_note

__all__ = ["Film", "default_trajectories", "film_angles", "write_animation"]

#: most frames a film may have (a GIF of more frames is large and slow to write)
MAX_FRAMES = 720
#: resolutions a film may be written at, dots per inch (its figure is the width of an A4 page's
#: text, 6.3 in at most: 80 dpi gives frames about 500 pixels wide)
DPI_RANGE = (30.0, 300.0)


def _mechanism_of(motion_or_mechanism) -> Mechanism:
    if isinstance(motion_or_mechanism, Motion):
        return motion_or_mechanism.mechanism
    if isinstance(motion_or_mechanism, Mechanism):
        return motion_or_mechanism
    raise InputError(f"a film is made of a Motion or a Mechanism, got {type(motion_or_mechanism).__name__}")


def _start_and_direction(motion_or_mechanism) -> tuple[float, int]:
    """Position 1 (rad) and the sense of rotation (+1 CCW, -1 CW) of a full-turn film: a motion's
    first angle and its direction; a mechanism's table start (``[dynamics] start_deg``, else the
    output's extreme position, else 0) and declared rotation (the sign of ``mean_speed``, else +1)."""
    if isinstance(motion_or_mechanism, Motion):
        return float(motion_or_mechanism.phi[0]), motion_or_mechanism.direction
    mech = motion_or_mechanism
    spec = section_of(mech, "dynamics")
    direction = spec.rotation if spec is not None else 1
    start = spec.start if spec is not None else "extreme"
    if isinstance(start, str) and mech.output is None:
        return 0.0, direction
    try:
        return float(table_angles(mech, 1, start, direction)[0]), direction
    except InputError as exc:          # e.g. an output that turns fully has no extreme position
        raise InputError(f"{exc}: the film cannot start at position 1 of the tables (film a Motion "
                         "analysed from the angle to start at instead)") from None


def film_angles(motion_or_mechanism: Motion | Mechanism, frames: int = 72) -> np.ndarray:
    """The input angles of the frames of a film, rad.

    Over a full turn: ``phi_k = phi_1 + s 2 pi k / frames``, k = 0 .. frames - 1, from position 1
    (a motion's first angle; a mechanism's table start: ``[dynamics] start_deg``, else the
    output's extreme position, else 0) in the sense of rotation s (a motion's direction; the sign
    of the scheme's ``[dynamics] mean_speed``, else +1, counter-clockwise). The last frame is one
    step before position 1, so that the GIF loops without a repeated frame.

    Over an input range (a, b): from a to b and back, in ``frames`` equal steps of the way
    there and back (a at frame 1, b at frame ``frames / 2 + 1`` when ``frames`` is even).

    Parameters
    ----------
    motion_or_mechanism : Motion or Mechanism
    frames : int
        Number of frames, 2 .. :data:`MAX_FRAMES`.

    Returns
    -------
    ndarray, shape (frames,)
    """
    mech = _mechanism_of(motion_or_mechanism)
    _check_count(frames)
    k = np.arange(frames)
    if mech.input_range is not None:
        a, b = (float(v) for v in mech.input_range)
        way = 2.0 * k / frames                       # 0 .. 2: there (0 .. 1) and back (1 .. 2)
        return a + (b - a) * np.where(way <= 1.0, way, 2.0 - way)
    phi0, direction = _start_and_direction(motion_or_mechanism)
    return phi0 + direction * 2 * np.pi * k / frames


def _check_count(frames) -> None:
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or not 2 <= frames <= MAX_FRAMES:
        raise InputError(f"frames must be a whole number from 2 to {MAX_FRAMES}, got {frames!r}")


def default_trajectories(mechanism: Mechanism) -> list[str]:
    """Points whose paths a film draws by default: the input link's pins away from the frame
    (the crank pin's circle) and the points of moving links that are at no pair and are no
    centre of mass (coupler points, the ends of rockers), in the order of the links.

    >>> import linkage
    >>> default_trajectories(linkage.load("four_bar"))
    ['A', 'E']
    >>> default_trajectories(linkage.load("slotted_link_two_dyad"))
    ['A', 'C']
    """
    mech = mechanism
    at_pairs = {p.point for p in mech.pairs.values()}
    out: list[str] = []
    for link in mech.inputs:
        for pair in mech.pairs.values():
            if link in pair.links and mech.frame not in pair.links and pair.point not in out:
                out.append(pair.point)
    for link in mech.moving_links:
        body = mech.links[link]
        for name, local in body.points.items():
            centre = body.mass_declared and math.dist(local, body.center_of_mass) < 1e-12 * mech.size
            if name not in at_pairs and not centre and name not in out:
                out.append(name)
    return out


class Film:
    """The frames of a film of one revolution (or of the input range there and back).

    Builds the motion at :func:`film_angles`, the scenes of every frame at one scale, within one
    set of limits and with the frame's supports in one place, and the figure (sized by the
    drawing, the width of an A4 page's text at most). The parts that stay (axes, grid, frame
    supports and guides, trajectories) are drawn once; :meth:`draw` draws a frame's moving parts
    (links, slots, sliders, pairs, points, their labels and the caption) on top, and
    :meth:`render` gives the frame's pixels by drawing only those over the parts that stay.

    Parameters
    ----------
    motion_or_mechanism : Motion or Mechanism
        What to film (a motion gives its mechanism, its first angle and its direction).
    frames : int
        Number of frames, 2 .. :data:`MAX_FRAMES`.
    trajectories : sequence of str, optional
        Points whose paths are drawn (dashed, whole, in every frame); default
        :func:`default_trajectories`; ``()`` for none.
    dpi : float
        Resolution of the frames, dots per inch.
    labels : bool or iterable of str
        As in :func:`~linkage.report.plots.draw_mechanism`.

    Attributes
    ----------
    angles : ndarray (frames,)
        Input angles of the frames, rad.
    motion : Motion
        Positions (order 0) at ``angles``.
    figure, ax
        The matplotlib figure and its axes (close with :meth:`close`).
    limits : (xmin, xmax, ymin, ymax)
        Axis limits of every frame, m.
    captions : list of str
        The caption of each frame.

    Raises
    ------
    InputError
        A frame's position cannot be assembled (naming the input angles), an unknown trajectory
        point, a bad number of frames or resolution.
    PlotExtraMissing
        matplotlib is not installed.
    """

    def __init__(self, motion_or_mechanism: Motion | Mechanism, frames: int = 72, *,
                 trajectories: Sequence[str] | None = None, dpi: float = 80.0,
                 labels: bool | Sequence[str] = True):
        pyplot()
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        _check_dpi(dpi)
        mech = _mechanism_of(motion_or_mechanism)
        self.angles = film_angles(motion_or_mechanism, frames)
        self.direction = _start_and_direction(motion_or_mechanism)[1] if mech.input_range is None else 0
        self.trajectories = default_trajectories(mech) if trajectories is None else list(trajectories)
        self.labels = labels
        self.motion = _assembled_motion(mech, self.angles)
        self.geometry = Geometry(self.motion, range(frames), self.trajectories)
        self.scenes = _scenes(self.geometry, frames)
        self.limits = drawing_limits(self.scenes, self.geometry)
        self.captions = _captions([self._caption(k) for k in range(frames)])
        lines = self.captions[0].count("\n") + 1
        chars = max(len(line) for c in self.captions for line in c.splitlines())
        self.figure, rects = figure_for(self.limits, caption_lines=lines, text_chars=chars)
        self.figure.set_dpi(dpi)
        FigureCanvasAgg(self.figure)          # pixels of its own, whatever pyplot's backend
        self.ax = self.figure.add_axes(rects[0])
        draw_scene(self.ax, _still(self.scenes[0]), self.geometry, self.limits, False, "")
        self._still_obstacles = scene_obstacles(_still(self.scenes[0]), self.geometry.unit, trajectory_step=3)
        self._moving: list = []
        self._background = None
        self._renderer = None

    def __len__(self) -> int:
        return len(self.angles)

    def draw(self, k: int):
        """Draw frame ``k`` (0 is the first) on :attr:`ax`, replacing the frame drawn before:
        ``figure.savefig`` then saves that frame.

        Returns
        -------
        list of matplotlib artists
            What frame ``k`` adds to the parts that stay (links, pairs, labels, the caption).
        """
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < len(self):
            raise InputError(f"frame must be a whole number from 0 to {len(self) - 1}, got {k!r}")
        for artist in self._moving:
            artist.remove()
        sc, u = self.scenes[k], self.geometry.unit
        moving = add_artists(self.ax, moving_artists(sc, self.geometry))
        if self.labels:
            drawn = scene_obstacles(_moving_part(sc), u, self._still_obstacles, trajectory_step=3)
            before = set(self.ax.texts)
            wanted = list(sc.points) if self.labels is True else [n for n in self.labels if n in sc.points]
            place_point_labels(self.ax, sc, wanted, drawn, FONT, PIN * u)
            moving += [t for t in self.ax.texts if t not in before]
        moving.append(self.ax.annotate(self.captions[k], (0.0, 1.0), xycoords="axes fraction", xytext=(0, TITLE_PAD),
                                       textcoords="offset points", ha="left", va="baseline", fontsize=FONT,
                                       gid="caption", annotation_clip=False))
        self._moving = moving
        return moving

    def render(self, k: int) -> np.ndarray:
        """The pixels of frame ``k``, ``(height, width, 4)`` RGBA, uint8: the frame's moving parts
        drawn, in the order of their layers, over the parts that stay (drawn once)."""
        canvas = self.figure.canvas
        if self._background is None or canvas.get_renderer() is not self._renderer:   # (again after a savefig)
            for artist in self._moving:
                artist.set_visible(False)
            canvas.draw()
            self._background = canvas.copy_from_bbox(self.figure.bbox)
            self._renderer = canvas.get_renderer()
        moving = self.draw(k)
        canvas.restore_region(self._background)
        for artist in sorted(moving, key=lambda a: a.get_zorder()):   # stable: the order drawn within a layer
            self.ax.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba()).copy()

    def close(self) -> None:
        """Close the figure."""
        pyplot().close(self.figure)

    def _caption(self, k: int) -> str:
        """The input angle of frame k in words: where the input link is, how far it has turned
        from position 1 (or which way it moves over a range), and what the dashed lines are;
        lines of at most :data:`~linkage.report.words.CAPTION_CHARS` characters."""
        import textwrap

        mech = self.motion.mechanism
        phi = float(self.angles[k])
        absolute = float(np.mod(np.degrees(phi), 360.0))
        if absolute >= 359.95:
            absolute = 0.0
        who = "input link" if mech.input_range is not None else "crank"
        where = f"the {who} at φ = {plain(absolute, '.1f')}° from the x axis"
        head = [f"{mech.name}: {where}"] if len(mech.name) + len(where) + 2 <= CAPTION_CHARS else [mech.name, where]
        if mech.input_range is None:
            turned = float(np.degrees(self.direction * (phi - self.angles[0])))
            sense = "counter-clockwise" if self.direction > 0 else "clockwise"
            moved = f"turned {plain(turned, '.1f')}° {sense} from position 1"
        else:
            a, b = np.degrees(mech.input_range)
            moved = f"on its way back from {b:.4g}° to {a:.4g}°" if 2 * k > len(self) else \
                f"on its way from {a:.4g}° to {b:.4g}°"
        note = textwrap.wrap(trajectory_note(mech, self.trajectories), CAPTION_CHARS) if self.trajectories else []
        return "\n".join(head + [moved] + note)


#: gap between the axes and the caption, points (matplotlib's title pad)
TITLE_PAD = 6.0
#: colours of a film's palette: the most frequent ones exactly, the antialiased edges to the
#: nearest (128 keep the edges smooth; a GIF of 256 is twice the size)
PALETTE = 128


def _captions(texts: list[str]) -> list[str]:
    """The captions padded to one number of lines, so that every frame has the same layout."""
    lines = max(t.count("\n") + 1 for t in texts)
    return [t + "\n" * (lines - 1 - t.count("\n")) for t in texts]


def _scenes(geometry: Geometry, frames: int) -> list[Scene]:
    """The scenes of every frame. Built without the trajectories (which every frame shares,
    added afterwards) so that each frame's search for its supports' places stays quick; the
    supports then stand where they cover least over the whole film."""
    paths = geometry.trajectories
    geometry.trajectories = []
    try:
        scenes = [geometry.scene(k) for k in range(frames)]
    finally:
        geometry.trajectories = paths
    curves = [(name, geometry.mech.point_link(name), geometry._sweep_points(name)) for name in paths]
    for sc in scenes:
        sc.trajectories = list(curves)
    _steady_supports(scenes, geometry.unit)
    return scenes


def _still(sc: Scene) -> Scene:
    """The parts of a scene that stay in every frame: the frame's points, supports and guides,
    and the trajectories."""
    return Scene(points={}, rails=sc.rails, pivots=sc.pivots, trajectories=sc.trajectories)


def _moving_part(sc: Scene) -> Scene:
    return Scene(points=sc.points, bodies=sc.bodies, slots=sc.slots, blocks=sc.blocks, pins=sc.pins, dots=sc.dots)


def _check_dpi(dpi) -> None:
    lo, hi = DPI_RANGE
    if isinstance(dpi, bool) or not isinstance(dpi, (int, float, np.integer, np.floating)) \
            or not lo <= float(dpi) <= hi:
        raise InputError(f"dpi must be a number from {lo:g} to {hi:g} dots per inch, got {dpi!r}")


def _assembled_motion(mech: Mechanism, angles: np.ndarray) -> Motion:
    """Positions at the frames' angles; InputError naming the angles where the mechanism cannot
    be assembled (there is nothing to draw there)."""
    motion = analyze(mech, angles, order=0, on_failure="mask")
    finite = np.all([np.all(np.isfinite(pose), axis=1) for pose in motion.poses.values()], axis=0)
    bad = (motion.status == CANNOT_ASSEMBLE) | ~finite
    if bad.any():
        deg = np.degrees(angles[bad])
        shown = ", ".join(f"{d:.6g}" for d in deg[:20]) + (" ..." if len(deg) > 20 else "")
        where = (f"its input range [{np.degrees(mech.input_range[0]):.6g}, {np.degrees(mech.input_range[1]):.6g}] deg"
                 if mech.input_range is not None else "a full turn")
        raise InputError(f"mechanism '{mech.name}' cannot be assembled at {len(deg)} of the film's {len(angles)} "
                         f"input angles over {where}: phi = {shown} deg; nothing to draw there (declare an input "
                         "range within which it assembles, range_deg in the scheme)")
    return motion


def _steady_supports(scenes: list[Scene], unit: float) -> None:
    """Stand every frame pivot on the same support in every frame (a support chosen frame by
    frame would jump): the first of :data:`~linkage.report.drawing.SUPPORT_DIRECTIONS` (down
    first) that covers at most :data:`SUPPORT_SLACK` times as many points of the links, guides,
    blocks and trajectories over the whole film as the direction that covers fewest. (A crank
    sweeps every direction alike; a support is moved off its usual place only for what stays in
    its way.) The trajectories, the same in every frame, count once."""
    if not scenes or not scenes[0].pivots:
        return
    bare = [Scene(points=sc.points, bodies=sc.bodies, slots=sc.slots, rails=sc.rails, blocks=sc.blocks)
            for sc in scenes]
    samples = np.vstack([scene_samples(sc, unit) for sc in bare]
                        + [scene_samples(Scene(trajectories=scenes[0].trajectories), unit)])
    directions = [_support_direction(p, samples, unit) for p, _ in scenes[0].pivots]
    for sc in scenes:
        sc.pivots = [(p, d) for (p, _), d in zip(sc.pivots, directions)]


#: how many times the fewest covered points a film's support may cover and still stand in its
#: preferred direction (down, then a wall on either side ...)
SUPPORT_SLACK = 1.25


def _support_direction(p: np.ndarray, samples: np.ndarray, unit: float) -> float:
    """Direction (rad) of a frame pivot's support over a film (see :func:`_steady_supports`);
    the support's region as :func:`~linkage.report.drawing._pivot_direction` measures it."""
    near = samples[(np.hypot(*(samples - p).T) > 0.5 * unit) & (np.hypot(*(samples - p).T) < 3.5 * unit)]
    covered = []
    for deg in SUPPORT_DIRECTIONS:
        tri, ground, strokes = support(p, math.radians(deg), unit)
        region = convex_hull(np.vstack([tri, ground, strokes.reshape(-1, 2)]))
        covered.append(int(np.sum(points_inside(region, near))))
    fewest = min(covered)
    first = next(k for k, c in enumerate(covered) if c <= SUPPORT_SLACK * fewest)
    return math.radians(SUPPORT_DIRECTIONS[first])


def write_animation(motion_or_mechanism: Motion | Mechanism, path, *, frames: int = 72, fps: float = 12,
                    trajectories: Sequence[str] | None = None, dpi: float = 80.0) -> Path:
    """Write the film of one revolution of the input (of its range there and back) as a GIF.

    Every frame is the mechanism drawn to scale as by
    :func:`~linkage.report.plots.draw_mechanism`, all at one scale and within one set of axis
    limits, captioned with the input angle; the frames follow the scheme's direction of rotation
    from position 1 (:func:`film_angles`). The file is the same, byte for byte, for the same call.
    72 frames at 80 dpi take a few seconds and well under 2 MB.

    Parameters
    ----------
    motion_or_mechanism : Motion or Mechanism
        What to film: a mechanism, or a motion (its mechanism, from its first angle in its
        direction).
    path : str or path-like
        The GIF to write (its folder must exist).
    frames : int
        Number of frames, 2 .. :data:`MAX_FRAMES`.
    fps : float
        Frames per second (0.5 .. 50; a GIF stores the delay in hundredths of a second).
    trajectories : sequence of str, optional
        Points whose paths are drawn, dashed and whole, in every frame (default:
        :func:`default_trajectories`; ``()`` for none).
    dpi : float
        Resolution, dots per inch (the figure is at most 6.3 in wide).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    InputError
        The mechanism cannot be assembled at some frames' angles (named), an unknown trajectory
        point, a bad number of frames, fps or dpi.
    PlotExtraMissing
        matplotlib is not installed.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import pathlib, tempfile, linkage
    >>> from PIL import Image
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     gif = write_animation(linkage.load("slider_crank"), pathlib.Path(folder) / "film.gif", frames=6)
    ...     Image.open(gif).n_frames
    6
    """
    pyplot()
    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.integer, np.floating)) \
            or not 0.5 <= float(fps) <= 50.0:
        raise InputError(f"fps must be a number from 0.5 to 50 frames per second, got {fps!r}")
    path = Path(path)
    if not path.parent.is_dir():
        raise InputError(f"cannot write the film {str(path)!r}: no folder {str(path.parent)!r}")
    film = Film(motion_or_mechanism, frames, trajectories=trajectories, dpi=dpi)
    try:
        writer = _film_writer(float(fps))
        with writer.saving(film.figure, str(path), dpi=film.figure.dpi):
            for k in range(len(film)):
                writer.add(film.render(k))
    finally:
        film.close()
    return path



def _film_writer(fps: float):
    """matplotlib's :class:`~matplotlib.animation.PillowWriter`, given the pixels of each frame
    (:meth:`Film.render`, which draws only what moves) instead of redrawing the whole figure, and
    writing every frame with one palette (quicker, a smaller file, no colour flicker)."""
    from matplotlib.animation import PillowWriter

    class FilmWriter(PillowWriter):
        def add(self, rgba: np.ndarray) -> None:
            """Append a frame, ``(height, width, 4)`` uint8, as RGB (the figure is opaque)."""
            from PIL import Image

            self._frames.append(Image.fromarray(np.ascontiguousarray(rgba[..., :3])))

        def grab_frame(self, **savefig_kwargs) -> None:
            self.add(np.asarray(self.fig.canvas.buffer_rgba()))

        def finish(self) -> None:
            self._frames = _one_palette(self._frames)
            super().finish()

    return FilmWriter(fps=fps)


def _one_palette(frames: list) -> list:
    """The frames (PIL RGB images) as palette images with one palette: the :data:`PALETTE` colours most
    frequent in three frames spread over the film (the exact colours of the paper, the lines and
    the links; ties by colour value); every other colour (the antialiased edges) takes its
    nearest, without dithering. Mapped exactly here (Pillow's own mapping to a given palette
    works on 6 bits per channel and would turn the white paper into a near-white grey)."""
    from PIL import Image

    if not frames:
        return frames
    packed = [_packed(np.asarray(frame)) for frame in frames]
    sample = np.concatenate([packed[k * len(frames) // 3] for k in range(3)])
    colours, counts = np.unique(sample, return_counts=True)
    chosen = colours[np.lexsort((colours, -counts))[:PALETTE]]
    palette = _unpacked(chosen).astype(float)
    present = np.zeros(1 << 24, dtype=bool)
    for p in packed:
        present[p] = True
    used = np.flatnonzero(present)
    nearest = np.empty(len(used), dtype=np.uint8)
    for start in range(0, len(used), 4096):          # blocks of colours: (4096, 256) distances at most
        block = _unpacked(used[start:start + 4096]).astype(float)
        distance = np.sum((block[:, None, :] - palette[None, :, :]) ** 2, axis=2)
        nearest[start:start + 4096] = np.argmin(distance, axis=1)
    lookup = np.zeros(1 << 24, dtype=np.uint8)
    lookup[used] = nearest
    flat = np.vstack([_unpacked(chosen), np.zeros((256 - len(chosen), 3), dtype=np.int64)]).astype(np.uint8)
    out = []
    for frame, p in zip(frames, packed):
        image = Image.frombytes("P", frame.size, lookup[p].tobytes())
        image.putpalette(flat.ravel().tolist())
        out.append(image)
    return out


def _packed(rgb: np.ndarray) -> np.ndarray:
    """RGB pixels ``(..., 3)`` uint8 as one integer each, ``0xRRGGBB``, flattened."""
    rgb = rgb.reshape(-1, 3).astype(np.int64)
    return (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]


def _unpacked(packed: np.ndarray) -> np.ndarray:
    """``0xRRGGBB`` integers as RGB rows ``(N, 3)``."""
    return np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1)
