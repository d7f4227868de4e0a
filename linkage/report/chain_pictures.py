"""Pictures of kinematic chains as graphs: links as nodes, revolute pairs as lines.

:func:`draw_chain` draws one chain: a binary link is a small open circle, a ternary link a filled
triangle, a quaternary one a filled square, a pentagonal and hexagonal one a filled pentagon and
hexagon (larger links a large dot), so the link kinds read at a glance in colour and in grey; the
frame, when given, is ringed and hatched as the ground, the input link ringed and marked with an
arrow. :func:`draw_chains` sets many chains in a grid, each titled with its name and assortment
(the picture of the sixteen eight-link chains in ``docs/synthesis.md``). :func:`chain_layout` is
the drawing's placement of the links: Tutte's barycentric drawing with one of the longest faces
outside, relaxed by stress majorization, keeping the drawing with the fewest crossing pairs, then
the most room between a link and the lines it is not on.

A chain is a ``networkx.Graph`` or any object with a ``graph`` attribute that is one (a
:class:`linkage.research.chains.Chain`, which also gives its ``name``, ``label`` and
``assortment`` to the titles). Pictures need matplotlib (the ``plot`` extra).

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import networkx as nx
>>> ax = draw_chain(nx.cycle_graph(4), frame=0, crank=1, title="four-bar")
>>> ax.get_title()
'four-bar'
>>> matplotlib.pyplot.close(ax.figure)
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Any

import networkx as nx
import numpy as np

from ..errors import InputError
from .style import FONT, PAGE_WIDTH, SMALL, new_figure, pyplot

__all__ = ["LINK_MARKERS", "chain_layout", "draw_chain", "draw_chains"]

#: pairs on a link -> (marker, size in points, face colour, name): binary links open and small
LINK_MARKERS = {
    2: ("o", 5.5, "white", "binary"),
    3: ("^", 11.0, "#1f5fa8", "ternary"),
    4: ("s", 10.0, "#c0392b", "quaternary"),
    5: ("p", 11.5, "#27864a", "pentagonal"),
    6: ("h", 11.5, "#7d3c98", "hexagonal"),
}
#: a link of more pairs than LINK_MARKERS holds
_LARGE_LINK = ("o", 12.0, "#6b4f2a", "more pairs")
FRAME_COLOUR = "#222222"
CRANK_COLOUR = "#d35400"
#: colour of the pair names written on the lines
PAIR_COLOUR = "#1a5276"


def _graph_of(chain) -> nx.Graph:
    graph = chain if isinstance(chain, nx.Graph) else getattr(chain, "graph", None)
    if not isinstance(graph, nx.Graph):
        raise InputError(f"a chain to draw is a networkx graph or has one as .graph, not {type(chain).__name__}")
    return graph


def _crossings(points: np.ndarray, ends: np.ndarray) -> int:
    """How many pairs of pairs (edges) without a common link cross: proper intersections of the
    segments between ``points`` (n, 2) at the ``ends`` (e, 2) of each edge."""
    first, second = np.triu_indices(len(ends), k=1)
    a, b, c, d = ends[first, 0], ends[first, 1], ends[second, 0], ends[second, 1]
    apart = (a != c) & (a != d) & (b != c) & (b != d)
    pa, pb, pc, pd = points[a], points[b], points[c], points[d]

    def side(p, q, r):
        return (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])

    cross = (side(pa, pb, pc) * side(pa, pb, pd) < 0) & (side(pc, pd, pa) * side(pc, pd, pb) < 0)
    return int(np.count_nonzero(cross & apart))


def _clearance(points: np.ndarray, ends: np.ndarray) -> float:
    """The smallest distance from a link to another link or to a pair (edge) it is not in, over
    the drawing's size (larger is easier to read)."""
    size = float(np.ptp(points, axis=0).max()) or 1.0
    n = len(points)
    gaps = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=2)[np.triu_indices(n, k=1)]
    start, span = points[ends[:, 0]], points[ends[:, 1]] - points[ends[:, 0]]           # (e, 2)
    along = np.einsum("nek,ek->ne", points[:, None, :] - start[None], span) / np.maximum(
        np.einsum("ek,ek->e", span, span), 1e-300)
    nearest = start[None] + np.clip(along, 0.0, 1.0)[..., None] * span[None]            # (n, e, 2)
    to_edge = np.linalg.norm(points[:, None, :] - nearest, axis=2)
    on_edge = (np.arange(n)[:, None] == ends[None, :, 0]) | (np.arange(n)[:, None] == ends[None, :, 1])
    return float(min(gaps.min(initial=size), to_edge[~on_edge].min(initial=size))) / size


def _outer_cycles(graph: nx.Graph, most: int = 4) -> list[list]:
    """Cycles to put on the outside of a drawing: the faces of a planar embedding (a planar
    graph), or a cycle basis, longest first (at most ``most``)."""
    planar, embedding = nx.check_planarity(graph)
    cycles = []
    if planar:
        seen: set = set()
        for u, v in embedding.edges():
            if (u, v) not in seen:
                cycles.append(list(embedding.traverse_face(u, v, mark_half_edges=seen)))
    else:
        cycles = [list(cycle) for cycle in nx.cycle_basis(graph)]
    cycles.sort(key=lambda cycle: (-len(cycle), sorted(map(str, cycle))))
    return cycles[:most]


def _tutte(graph: nx.Graph, nodes: list, outer: list) -> np.ndarray:
    """Tutte's barycentric placement: ``outer`` on the unit circle, every other link at the mean
    of its neighbours (a planar drawing when the outer cycle is a face), (n, 2)."""
    index = {node: k for k, node in enumerate(nodes)}
    positions = np.zeros((len(nodes), 2))
    angle = np.linspace(0.0, 2 * math.pi, len(outer), endpoint=False) + math.pi / 2
    fixed = np.zeros(len(nodes), dtype=bool)
    for node, a in zip(outer, angle):
        positions[index[node]] = (math.cos(a), math.sin(a))
        fixed[index[node]] = True
    free = np.flatnonzero(~fixed)
    if free.size:
        laplacian = nx.laplacian_matrix(graph, nodelist=nodes).toarray().astype(float)
        rhs = -laplacian[np.ix_(free, np.flatnonzero(fixed))] @ positions[fixed]
        positions[free] = np.linalg.solve(laplacian[np.ix_(free, free)], rhs)
    return positions


def _relax(distances: np.ndarray, start: np.ndarray, ends: np.ndarray, iterations: int = 100,
           room: float = 0.12) -> np.ndarray:
    """Stress majorization (SMACOF, weights 1/d^2) from ``start`` (n, 2) towards a drawing whose
    distances match the graph distances ``distances`` (n, n), each step shortened (halved up to
    five times, else the relaxation stops) so that no pair of edges crosses that did not before and
    no link comes closer to another or to an edge than ``room`` of the drawing's size (unless it
    already was)."""
    n = len(distances)
    off = ~np.eye(n, dtype=bool)
    weights = np.zeros_like(distances)
    weights[off] = distances[off] ** -2.0
    inverse = np.linalg.pinv(np.diag(weights.sum(axis=1)) - weights)
    positions = start.copy()
    crossings = _crossings(positions, ends)
    clearance = _clearance(positions, ends)
    for _ in range(iterations):
        gaps = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=2)
        ratio = np.zeros_like(gaps)
        apart = off & (gaps > 1e-12)
        ratio[apart] = weights[apart] * distances[apart] / gaps[apart]
        target = inverse @ ((np.diag(ratio.sum(axis=1)) - ratio) @ positions)
        target += positions.mean(axis=0) - target.mean(axis=0)
        for step in (1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125):
            trial = positions + step * (target - positions)
            if _crossings(trial, ends) <= crossings and _clearance(trial, ends) >= min(clearance, room):
                break
        else:
            break
        moved = np.abs(trial - positions).max()
        positions = trial
        clearance = _clearance(positions, ends)
        if moved < 1e-6:
            break
    return positions


def _stress(distances: np.ndarray, points: np.ndarray) -> float:
    """The weighted stress ``sum (|x_i - x_j| / d_ij - s)^2`` of a drawing at its best scale s,
    over the pairs of links (smaller: the drawing's distances follow the graph's)."""
    first, second = np.triu_indices(len(points), k=1)
    ratio = np.linalg.norm(points[first] - points[second], axis=1) / distances[first, second]
    return float(np.sum((ratio / ratio.mean() - 1.0) ** 2))


def chain_layout(chain) -> dict:
    """Positions of the links for a drawing, ``{link: (x, y)}``, deterministic.

    From each of the longest faces of a planar embedding (or cycles, for a non-planar graph) put
    on a circle: Tutte's barycentric placement of the other links (no crossing for a planar
    chain), and that placement relaxed by stress majorization towards distances equal to the
    graph distances (without adding a crossing or crowding a link, without adding a crossing,
    freely); the drawing kept has the fewest crossing pairs, then no link within 0.04 of the
    drawing's size of another link or of a pair it is not in, then the largest such clearance up
    to 0.12, then the least stress.
    """
    graph = _graph_of(chain)
    try:
        nodes = sorted(graph)
    except TypeError:
        nodes = list(graph)
    if len(nodes) < 3 or not nx.is_connected(graph) or graph.number_of_edges() < len(nodes):
        return {node: (float(x), float(y)) for node, (x, y) in nx.circular_layout(nodes).items()}
    index = {node: k for k, node in enumerate(nodes)}
    pairs = tuple(sorted(tuple(sorted((index[a], index[b]))) for a, b in graph.edges()))
    placement = _placement(len(nodes), pairs)
    return {node: (float(x), float(y)) for node, (x, y) in zip(nodes, placement)}


@functools.lru_cache(maxsize=4096)
def _placement(links: int, pairs: tuple) -> np.ndarray:
    """:func:`chain_layout` of the graph on 0 .. links-1 with these edges, (links, 2), remembered."""
    graph = nx.Graph(list(pairs))
    graph.add_nodes_from(range(links))
    nodes = list(range(links))
    ends = np.array(pairs, dtype=int)
    distances = nx.floyd_warshall_numpy(graph, nodelist=nodes)
    best, best_score = None, None
    # a small fixed nudge: Tutte's drawing puts a string of binary links inside a face on a straight
    # line, where two strings between the same links coincide and relaxation alone keeps them so
    nudge = 0.03 * np.random.default_rng(links).standard_normal((links, 2))
    for outer in _outer_cycles(graph):
        start = _tutte(graph, nodes, outer)
        nudged = start + nudge
        for placement in (start, _relax(distances, start, ends), _relax(distances, nudged, ends),
                          _relax(distances, nudged, ends, room=0.0), _relax(distances, nudged, ends[:0], room=0.0)):
            clearance = _clearance(placement, ends)
            score = (_crossings(placement, ends), clearance < 0.04, -round(min(clearance, 0.12), 2),
                     _stress(distances, placement))
            if best_score is None or score < best_score:
                best, best_score = placement, score
    best.setflags(write=False)
    return best


def _marker(pairs: int) -> tuple:
    return LINK_MARKERS.get(pairs, _LARGE_LINK) if pairs >= 2 else LINK_MARKERS[2]


def _title(chain, index: int | None) -> str:
    name = getattr(chain, "name", None) or (f"chain {index}" if index is not None else "")
    label = getattr(chain, "label", None)
    assortment = getattr(chain, "assortment", None)
    lines = [f"{name} {label}" if label else name]
    if assortment:
        lines.append("(" + ", ".join(str(n) for n in assortment) + ")")
    return "\n".join(line for line in lines if line)


def draw_chain(chain, ax=None, *, frame=None, crank=None, title: str | None = None, numbers: bool = False,
               positions: dict | None = None, pairs: dict | None = None):
    """Draw a chain's graph: links as nodes (shape by number of pairs), pairs as lines.

    Parameters
    ----------
    chain : networkx.Graph or object with ``.graph``
        The chain (a :class:`~linkage.research.chains.Chain` gives its name to the default title).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when omitted.
    frame, crank : node, optional
        The frame link (ringed, with ground hatching) and the input link (ringed, with an arrow).
    title : str, optional
        The title; by default the chain's name, classical name and assortment when it has them.
    numbers : bool
        Write each link's number beside it.
    positions : dict, optional
        ``{link: (x, y)}``; :func:`chain_layout` by default.
    pairs : dict, optional
        ``{(link, link): name}``: each pair's name written at the middle of its line (a
        mechanism's pair letters, as its drawing writes them).

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    InputError
        ``frame`` or ``crank`` is not a link of the chain, or the crank is not paired with the frame.
    PlotExtraMissing
        matplotlib is not installed.
    """
    graph = _graph_of(chain)
    for role, link in (("frame", frame), ("input", crank)):
        if link is not None and link not in graph:
            raise InputError(f"{role} link {link!r} is not a link of the chain (links {sorted(graph)})")
    if frame is not None and crank is not None and not graph.has_edge(frame, crank):
        raise InputError(f"input link {crank!r} is not paired with the frame link {frame!r}")
    if ax is None:
        ax = new_figure(PAGE_WIDTH / 2, PAGE_WIDTH / 2).add_subplot()
    positions = chain_layout(graph) if positions is None else positions
    points = np.array([positions[node] for node in graph], dtype=float).reshape(-1, 2)
    size = float(np.ptp(points, axis=0).max()) if len(points) > 1 else 1.0
    size = size or 1.0

    for a, b in graph.edges():
        (xa, ya), (xb, yb) = positions[a], positions[b]
        ax.plot([xa, xb], [ya, yb], color="#555555", lw=1.4, zorder=1, solid_capstyle="round")
        name = None if pairs is None else pairs.get((a, b), pairs.get((b, a)))
        if name is not None:
            ax.text((xa + xb) / 2, (ya + yb) / 2, str(name), fontsize=SMALL - 1, color=PAIR_COLOUR, ha="center",
                    va="center", zorder=5, bbox={"boxstyle": "round,pad=0.12", "fc": "white", "ec": "none"})
    for node in graph:
        x, y = positions[node]
        marker, points_size, face, _ = _marker(graph.degree(node))
        ax.plot([x], [y], marker=marker, ms=points_size, mfc=face, mec="#222222", mew=1.1, ls="none", zorder=3)
        if numbers:
            ax.annotate(str(node), (x, y), xytext=(5, 5), textcoords="offset points", fontsize=SMALL - 1,
                        color="#333333", zorder=4)
    if frame is not None:
        x, y = positions[frame]
        ax.plot([x], [y], marker="o", ms=19, mfc="none", mec=FRAME_COLOUR, mew=1.8, ls="none", zorder=2)
        step = 0.045 * size
        base = y - 0.1 * size
        ax.plot([x - 2.2 * step, x + 2.2 * step], [base, base], color=FRAME_COLOUR, lw=1.4, zorder=2)
        for k in range(-2, 3):
            ax.plot([x + k * step, x + k * step - step], [base, base - step], color=FRAME_COLOUR, lw=1.0, zorder=2)
    if crank is not None:
        x, y = positions[crank]
        ax.plot([x], [y], marker="o", ms=19, mfc="none", mec=CRANK_COLOUR, mew=1.8, ls="none", zorder=2)
        ax.annotate("", xy=(x, y), xytext=(x - 0.16 * size, y + 0.16 * size), zorder=2,
                    arrowprops={"arrowstyle": "-|>", "color": CRANK_COLOUR, "lw": 1.4, "shrinkA": 0, "shrinkB": 9})
    centre = (points.min(axis=0) + points.max(axis=0)) / 2 if len(points) else np.zeros(2)
    half = 0.68 * size                                  # the drawing and a margin for the marks
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(_title(chain, None) if title is None else title, fontsize=SMALL)
    return ax


def draw_chains(chains: Sequence[Any], *, columns: int = 4, title: str | None = None,
                frames: Sequence | None = None, cranks: Sequence | None = None, numbers: bool = False):
    """Many chains in a grid, each titled by its name (and classical name, assortment), a legend of
    the link kinds below.

    Parameters
    ----------
    chains : sequence of chains
        As :func:`draw_chain` takes them.
    columns : int
        Pictures per row.
    title : str, optional
        The figure's title.
    frames, cranks : sequence, optional
        A frame and an input link per chain (None where unmarked).
    numbers : bool
        Write the link numbers.

    Returns
    -------
    matplotlib Figure
    """
    if not chains:
        raise InputError("no chain to draw")
    if int(columns) < 1:
        raise InputError(f"columns = {columns!r}: at least one picture a row")
    columns = min(int(columns), len(chains))
    rows = math.ceil(len(chains) / columns)
    cell = PAGE_WIDTH / columns
    figure = new_figure(PAGE_WIDTH, (cell + 0.35) * rows + 0.6)
    grid = figure.subplots(rows, columns, squeeze=False)
    frames = list(frames) if frames is not None else [None] * len(chains)
    cranks = list(cranks) if cranks is not None else [None] * len(chains)
    degrees = set()
    for k, ax in enumerate(grid.ravel()):
        if k >= len(chains):
            ax.set_axis_off()
            continue
        graph = _graph_of(chains[k])
        degrees |= {d for _, d in graph.degree}
        draw_chain(chains[k], ax, frame=frames[k], crank=cranks[k], numbers=numbers,
                   title=_title(chains[k], k + 1))
    plt = pyplot()
    handles = []
    for pairs in sorted(degrees):
        marker, size, face, name = _marker(pairs)
        handles.append(plt.Line2D([], [], marker=marker, ms=size * 0.8, mfc=face, mec="#222222", ls="none",
                                  label=f"{name} link"))
    handles.append(plt.Line2D([], [], color="#555555", lw=1.4, label="revolute pair"))
    if any(f is not None for f in frames):
        handles.append(plt.Line2D([], [], marker="o", ms=11, mfc="none", mec=FRAME_COLOUR, mew=1.8, ls="none",
                                  label="frame"))
    if any(c is not None for c in cranks):
        handles.append(plt.Line2D([], [], marker="o", ms=11, mfc="none", mec=CRANK_COLOUR, mew=1.8, ls="none",
                                  label="input"))
    figure.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 5), fontsize=SMALL,
                  frameon=False)
    if title:
        figure.suptitle(title, fontsize=FONT)
    return figure
