"""Geometry that runs: dimensions drawn for a mechanism of the synthesis until one turns its crank fully.

For each mechanism (:class:`~.synthesis.Topology`) :func:`search_geometry` draws dimensions
reproducibly (a generator seeded by the run's seed and the mechanism's id, so that the result of
one mechanism does not depend on the others or on the workers): every pin at a random point of the
unit square at the reference angle, the crank's pins 0.04 .. 0.15 m from its bearing. The drawn
position is a position of the mechanism by construction (the reference position of
:mod:`~.placement`, with an all-revolute assignment); each group keeps its branch there (a dyad)
or its assembly mode, declared by a readable condition (a group solved by Newton's method), as
``linkage enumerate`` does. A draw is kept when its mode is followed over a turn (the cheap walk
of :func:`~.placement.placement`), the written scheme loads, and the feasibility rules pass
(:func:`linkage.kinematics.feasibility.check`: assembled at every angle of a 1 deg sweep,
regular, no change point, every dyad's transmission angle at least the minimum) with no group
close to a singular position (:func:`~.placement.too_close_to_singular`). Where the whole turn
fails, the crank is shortened (:data:`CRANK_FACTORS`) before the next draw.
:func:`search_all` runs the searches in this process, in worker processes or on a Dask cluster.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import math
import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import networkx as nx
import numpy as np

from assur.base import OK

from ..errors import AssemblyError, InputError, LinkageError, SchemeError
from ..kinematics.feasibility import Requirements, check, sweep_angles
from ..kinematics.motion import BranchWarning, analyze
from ..model.builder import MechanismBuilder
from ..model.mechanism import Mechanism
from ..model.scheme import dumps, loads
from ..report.chain_pictures import chain_layout, draw_chain
from ..report.drawing import draw_mechanism
from ..report.style import pyplot
from ..structure import structure_of
from ..workers import run_all
from .assignments import Assignment, PairKind, Reference
from .chains import Chain
from .geometry import one_line
from .placement import (
    CONDITION_TRIALS,
    MIN_CONDITIONING,
    declared_combination,
    placement,
    singular_words,
    too_close_to_singular,
    tracked_groups,
)
from .synthesis import Topology, catalogue

__all__ = [
    "CRANK_FACTORS",
    "DEFAULT_DRAWS",
    "DEFAULT_MIN_TRANSMISSION_DEG",
    "Found",
    "picture",
    "search_all",
    "search_geometry",
    "write_atlas",
]

#: draws of dimensions per mechanism (each tried with the crank lengths of CRANK_FACTORS)
DEFAULT_DRAWS = 40
#: the smallest transmission angle of every dyad over the turn, deg
DEFAULT_MIN_TRANSMISSION_DEG = 20.0
#: lengths of the drawn crank tried in turn, as fractions of the drawn one
CRANK_FACTORS = (1.0, 0.5)
#: the crank's pins lie this far from its bearing, m (the other pins anywhere in the unit square)
CRANK_RADII = (0.04, 0.15)
#: two pins of one link closer than this, or a pin this close to the line through two others, are drawn again, m
MIN_PIN_GAP = 0.05


@dataclass(frozen=True)
class Found:
    """The outcome of one mechanism's geometry search.

    Attributes
    ----------
    id : str
        The mechanism's id (:attr:`~.synthesis.Topology.id`).
    found : bool
        A geometry that turns fully was found within the draws.
    draws : int
        Draws tried (up to the one found).
    crank_factor : float or None
        The crank's length in that geometry as a fraction of the drawn one.
    min_transmission_angle_deg : float or None
        Its smallest transmission angle over the turn, deg (None: no dyad has one, or not found).
    min_conditioning : float or None
        Its smallest conditioning of any group over the turn (1 well proportioned, 0 singular).
    scheme : str or None
        The scheme file's text (found only).
    note : str
        Why none was found: the reason of the first draw's rejection.
    """

    id: str
    found: bool
    draws: int
    crank_factor: float | None
    min_transmission_angle_deg: float | None
    min_conditioning: float | None
    scheme: str | None
    note: str


def _rng(seed: int, key: str) -> np.random.Generator:
    """The generator of one mechanism's draws: seeded by ``seed`` and a digest of ``key``."""
    digest = int.from_bytes(hashlib.sha256(key.encode()).digest()[:8], "little")
    return np.random.default_rng([int(seed), digest])


def _draw(topology: Topology, rng: np.random.Generator) -> tuple[dict[str, np.ndarray], float]:
    """Global pin positions ``{pair: (2,)}`` (m) at the reference angle, and that angle (rad): the
    crank's pins 0.04 .. 0.15 m from its bearing ``O``, the others uniform in the unit square; drawn
    again until the pins of every link are spread (:func:`_spread`)."""
    names = [p for p, _, _ in topology.pairs]
    on_crank = [p for p, a, b in topology.pairs if "1" in (a, b) and p != "O"]
    while True:
        points = {p: rng.uniform(0.0, 1.0, 2) for p in names}
        points["O"] = rng.uniform(0.3, 0.7, 2)
        for p in on_crank:
            angle, radius = rng.uniform(0, 2 * np.pi), rng.uniform(*CRANK_RADII)
            points[p] = points["O"] + radius * np.array([math.cos(angle), math.sin(angle)])
        if all(_spread([points[p] for p, a, b in topology.pairs if link in (a, b)])
               for link in {k for _, a, b in topology.pairs for k in (a, b)}):
            first = points[on_crank[0]] - points["O"]
            return points, math.atan2(first[1], first[0])


def _spread(pins: list[np.ndarray]) -> bool:
    """Whether the pins of one link are :data:`MIN_PIN_GAP` apart and each that far from the line
    through any two others (no sliver of a ternary link)."""
    if any(np.linalg.norm(p - q) < MIN_PIN_GAP for i, p in enumerate(pins) for q in pins[:i]):
        return False
    for i, j in itertools.combinations(range(len(pins)), 2):
        along = (pins[j] - pins[i]) / np.linalg.norm(pins[j] - pins[i])
        for k in set(range(len(pins))) - {i, j}:
            offset = pins[k] - pins[i]
            if abs(along[0] * offset[1] - along[1] * offset[0]) < MIN_PIN_GAP:
                return False
    return True


def _source(topology: Topology, points: dict[str, np.ndarray], phi: float) -> tuple[Mechanism, Reference]:
    """The drawn mechanism (no assembly conditions, no output) and its reference position: the
    frame's points global, the crank's axis along its first pin, every other link's origin at its
    first pin (by pair name), not turned."""
    links = sorted({k for _, a, b in topology.pairs for k in (a, b)}, key=int)
    poses = {}
    for link in links:
        own = [p for p, a, b in topology.pairs if link in (a, b)]
        if link == "0":
            poses[link] = np.zeros(3)
        elif link == "1":
            poses[link] = np.array([*points["O"], phi])
        else:
            poses[link] = np.array([*points[own[0]], 0.0])
    ref = Reference(phi, poses, {p: (p, points[p]) for p in points}, 1.0)
    builder = MechanismBuilder(f"synthesis {topology.id}", frame="0")
    for link in links:
        own = [p for p, a, b in topology.pairs if link in (a, b)]
        builder.link(link, points={p: ref.to_local(link, points[p]) for p in own})
    for p, a, b in topology.pairs:
        builder.revolute(p, a, b, at=p)
    builder.inputs("1")
    source = builder.build()
    return source, replace(ref, size=source.size)


def _all_revolute(topology: Topology) -> Assignment:
    return Assignment(tuple(PairKind(p, "R") for p, _, _ in topology.pairs if p != "O"))


def _scheme_text(topology: Topology, mech: Mechanism, seed: int, draw: int, factor: float) -> str:
    """The scheme file: comments saying where it comes from, then the scheme."""
    header = [f"# {topology.id}: {_description(topology)}",
              (f"# written by `linkage synthesize --links {topology.links} --with-geometry --seed {seed}`: draw "
               f"{draw}, crank {factor:g} of the drawn one (docs/synthesis.md)")]
    return "\n".join(header) + "\n" + dumps(mech)


def _declared(topology: Topology, source: Mechanism, ref: Reference, factor: float) -> Mechanism | str:
    """The mechanism with the drawn geometry (crank ``factor``), its branches and modes declared,
    loaded from its scheme text; or why its mode is no sensible default over a turn."""
    assignment = _all_revolute(topology)
    place = placement(source, ref, assignment, factor)
    if place.problem is not None:
        return place.problem
    structure = place.structure
    tracked = tracked_groups(structure)
    reasons = []
    for choice in range(CONDITION_TRIALS if tracked else 1):
        try:
            built = declared_combination(source, assignment, factor, ref, None, choice, structure,
                                         place if tracked else None)
            mech = loads(dumps(replace(built, name=topology.id, description=_description(topology))),
                         source=f"{topology.id}.toml")
        except AssemblyError as exc:        # no further readable condition
            reasons.append(one_line(exc))
            break
        except SchemeError as exc:
            reasons.append(one_line(exc))
            continue
        if not tracked:
            return mech
        motion = analyze(mech, [ref.phi], order=0, on_failure="mask")
        miss = place.mismatch({k: motion.poses[k][0] for group in structure.groups for k in group.links})
        if motion.status[0] == OK and miss <= 1e-8 * mech.size:
            return mech
        reasons.append(f"the traced mode at the reference angle is not the drawn position's ({miss:.3g} m apart)")
    return "; ".join(reasons) or "no readable assembly condition"


def _description(topology: Topology) -> str:
    label = f" ({topology.chain_label})" if topology.chain_label else ""
    return (f"Chain {topology.chain}{label}, frame link {topology.frame}, crank link {topology.crank}: "
            f"{topology.formula}")


def _judged(mech: Mechanism, min_angle: float) -> tuple[str | None, dict]:
    """Why ``mech`` does not run (the feasibility rules, the transmission angle when it has a dyad; a
    group close to a singular position), or None; the check's figures."""
    dyads = any(len(group.links) == 2 for group in structure_of(mech).groups)
    verdict = check(mech, Requirements(min_transmission_angle_deg=min_angle if dyads else None))
    if not verdict.feasible:
        return verdict.reason, verdict.figures
    if verdict.figures["min_conditioning"] >= MIN_CONDITIONING:
        return None, verdict.figures
    motion = analyze(mech, sweep_angles(mech, 360), order=0, on_failure="mask")
    for group in motion.structure.groups:
        ratios = motion.conditioning[repr(group)]
        if too_close_to_singular(group, ratios):
            largest = None if len(group.links) == 2 else float(np.nanmax(ratios))
            return singular_words(group, float(np.nanmin(ratios)), None, largest), verdict.figures
    return None, verdict.figures


def search_geometry(topology: Topology, seed: int = 0, *, draws: int = DEFAULT_DRAWS,
                    min_transmission_angle_deg: float = DEFAULT_MIN_TRANSMISSION_DEG) -> Found:
    """Draw dimensions for ``topology`` until a geometry turns its crank fully (module docstring).

    Parameters
    ----------
    topology : Topology
        The mechanism.
    seed : int
        Seed of the draws (with the mechanism's id: the same seed gives the same geometry).
    draws : int
        Most draws (each tried with the crank lengths of :data:`CRANK_FACTORS`).
    min_transmission_angle_deg : float
        Smallest transmission angle allowed over the turn for every dyad, deg in (0, 90).

    Returns
    -------
    Found
    """
    rng = _rng(seed, topology.id)
    first_reason = None
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        warnings.simplefilter("ignore", BranchWarning)
        for draw in range(1, draws + 1):
            source, ref = _source(topology, *_draw(topology, rng))
            for factor in CRANK_FACTORS:
                try:
                    mech = _declared(topology, source, ref, factor)
                    if isinstance(mech, str):
                        problem, figures = mech, {}
                    else:
                        problem, figures = _judged(mech, min_transmission_angle_deg)
                except LinkageError as exc:
                    problem, figures = one_line(exc), {}
                if problem is None:
                    return Found(topology.id, True, draw, factor, figures.get("min_transmission_angle_deg"),
                                 figures.get("min_conditioning"), _scheme_text(topology, mech, seed, draw, factor), "")
                first_reason = first_reason or problem
    return Found(topology.id, False, draws, None, None, None, None,
                 f"no geometry turns fully in {draws} draws (first draw: {first_reason})")


def search_all(topologies: Sequence[Topology], seed: int = 0, *, draws: int = DEFAULT_DRAWS,
               min_transmission_angle_deg: float = DEFAULT_MIN_TRANSMISSION_DEG, workers: int = 1,
               scheduler: str | None = None, progress: Callable[[Iterable, int], Iterable] | None = None) -> list[Found]:
    """:func:`search_geometry` of every mechanism, in order: in this process, in ``workers`` worker
    processes, or on the Dask distributed cluster at ``scheduler`` (``tcp://host:8786``, the 'dask'
    extra); the results do not depend on where they run. ``progress(iterable, total)`` wraps the
    stream of results (a tqdm bar).

    Raises
    ------
    InputError
        For a bad number of workers or draws, a minimum angle out of (0, 90), or a scheduler that
        cannot be reached (naming it).
    """
    if not (isinstance(workers, int) and workers >= 1):
        raise InputError(f"workers must be a whole number >= 1, got {workers!r}")
    if not (isinstance(draws, int) and draws >= 1):
        raise InputError(f"draws must be a whole number >= 1, got {draws!r}")
    if not (0.0 < float(min_transmission_angle_deg) < 90.0):
        raise InputError(f"the minimum transmission angle must be in (0, 90) deg, got {min_transmission_angle_deg!r}")
    calls = [(t, seed, draws, float(min_transmission_angle_deg)) for t in topologies]
    stream = run_all(_search, calls, workers=workers, scheduler=scheduler)
    if progress is not None:
        stream = progress(stream, len(topologies))
    return list(stream)


def _search(topology: Topology, seed: int, draws: int, min_transmission_angle_deg: float) -> Found:
    """:func:`search_geometry` with its options by position (for :func:`linkage.workers.run_all`)."""
    return search_geometry(topology, seed, draws=draws, min_transmission_angle_deg=min_transmission_angle_deg)


# ----------------------------------------------------------------------------------------------
# the atlas: tables, schemes and pictures
# ----------------------------------------------------------------------------------------------


def write_atlas(folder: str | Path, chain_list: Sequence[Chain], topologies: Sequence[Topology],
                results: Sequence[Found] | None = None, *, seed: int = 0, pictures: bool = True) -> list[Path]:
    """Write the synthesis into ``folder`` (created): ``chains.csv``, ``mechanisms.csv``,
    ``groups.csv`` (the catalogue), ``<id>.toml`` for every mechanism with a geometry (``results``
    in the order of ``topologies``) and, with ``pictures``, ``<id>.png``: the graph (frame and crank
    marked) and, with a geometry, the mechanism drawn at its first position. Returns the files.

    Raises
    ------
    InputError
        When the folder cannot be created or written (naming it).
    """
    folder = Path(folder)
    found = {r.id: r for r in results or ()}
    by_name = {c.name: c for c in chain_list}
    files: dict[str, str | bytes] = {
        "chains.csv": _csv({"chain": [c.name for c in chain_list], "label": [c.label or "" for c in chain_list],
                            "assortment": [" ".join(map(str, c.assortment)) for c in chain_list],
                            "edges": [" ".join(f"{a}-{b}" for a, b in c.edges) for c in chain_list]}),
        "groups.csv": _csv({k: [getattr(g, k) for g in catalogue(topologies)]
                            for k in ("kind", "group_class", "links", "pairs", "mechanisms", "occurrences")}),
        "mechanisms.csv": _csv(_mechanism_rows(topologies, found if results is not None else None)),
    }
    for t in topologies:
        r = found.get(t.id)
        if r is not None and r.scheme is not None:
            files[f"{t.id}.toml"] = r.scheme
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for name, text in files.items():
            (folder / name).write_text(text, encoding="utf-8")
        written = [folder / name for name in files]
        if pictures:
            for t in topologies:
                r = found.get(t.id)
                path = folder / f"{t.id}.png"
                picture(by_name[t.chain], t, r.scheme if r is not None else None, path)
                written.append(path)
    except OSError as exc:
        raise InputError(f"{folder}: cannot be written ({exc.strerror or exc})") from None
    return written


def _mechanism_rows(topologies: Sequence[Topology], found: dict[str, Found] | None) -> dict[str, list]:
    rows = {"mechanism": [t.id for t in topologies], "chain": [t.chain for t in topologies],
            "chain_label": [t.chain_label or "" for t in topologies], "inversion": [t.inversion for t in topologies],
            "frame": [t.frame for t in topologies], "crank": [t.crank for t in topologies],
            "formula": [t.formula for t in topologies], "class": [t.mechanism_class for t in topologies]}
    if found is not None:
        results = [found[t.id] for t in topologies]
        rows["geometry"] = ["yes" if r.found else "no" for r in results]
        rows["draws"] = [r.draws for r in results]
        rows["min_transmission_angle_deg"] = ["" if r.min_transmission_angle_deg is None
                                              else f"{r.min_transmission_angle_deg:.6g}" for r in results]
        rows["scheme"] = [f"{r.id}.toml" if r.found else "" for r in results]
        rows["note"] = [r.note for r in results]
    return rows


def _csv(columns: dict[str, list]) -> str:
    """CSV text of a table of equal-length columns (the header alone when it has no rows)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(list(columns))
    writer.writerows(zip(*columns.values()))
    return buffer.getvalue()


def picture(chain: Chain, topology: Topology, scheme: str | None, path: str | Path) -> Path:
    """``path`` (PNG): the mechanism's graph (:func:`~linkage.report.chain_pictures.draw_chain`: its
    frame and crank marked, the links numbered and the pairs lettered by the mechanism's names) and, with a ``scheme`` text, the mechanism drawn at its first position (needs matplotlib)."""
    plt = pyplot()
    panels = 2 if scheme is not None else 1
    fig = plt.figure(figsize=(4.2 * panels, 4.4))
    try:
        ax = fig.add_subplot(1, panels, 1)
        names = {k: int(topology.names[k]) for k in range(chain.links)}
        layout = chain_layout(chain)
        draw_chain(nx.relabel_nodes(chain.graph, names), ax=ax, frame=0, crank=1, numbers=True,
                   positions={names[k]: xy for k, xy in layout.items()},
                   pairs={(int(a), int(b)): pair for pair, a, b in topology.pairs},
                   title=f"{topology.id}\n{topology.formula}")
        if scheme is not None:
            mech = loads(scheme, source=f"{topology.id}.toml")
            motion = analyze(mech, sweep_angles(mech, 36), order=0, on_failure="mask")
            draw_mechanism(motion, 0, ax=fig.add_subplot(1, panels, 2), trajectories=(), caption=False)
        fig.savefig(path, dpi=110)
    finally:
        plt.close(fig)
    return Path(path)

