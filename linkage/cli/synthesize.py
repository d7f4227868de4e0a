"""``linkage synthesize``: every 1-DOF mechanism of N links (chains, inversions, inputs), its Assur
groups and formula, and (``--with-geometry``) a geometry that turns its crank fully."""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from ..errors import InputError
from ..report import format_columns
from ..research.chains import chains
from ..research.synthesis import catalogue, mechanisms
from ..research.synthesis_geometry import (
    DEFAULT_DRAWS,
    DEFAULT_MIN_TRANSMISSION_DEG,
    search_all,
    write_atlas,
)
from .options import PROG, add_format_argument, note, out, whole

#: the chains' numbers of links with 1-DOF chains
LINKS = (4, 6, 8, 10, 12)


def add(sub) -> None:
    p = sub.add_parser(
        "synthesize", help="every 1-DOF mechanism of N links: chains, inversions, inputs, Assur groups, geometry",
        description="Structural synthesis (docs/synthesis.md): every non-isomorphic 1-DOF planar chain of N "
                    "links with revolute pairs and no rigid sub-chain (1, 2, 16, 230, 6856 chains for N = 4, 6, 8, "
                    "10, 12), each inversion (frame link, modulo the chain's symmetry) and input (a link pinned to "
                    "the frame, modulo the symmetry that keeps the frame), decomposed into Assur groups. Columns: "
                    "mechanism (chain-fFRAME-cCRANK, the chain's link numbers), chain, chain_label, inversion, "
                    "frame, crank, formula, class, and with --with-geometry: geometry (yes/no), draws, "
                    "min_transmission_angle_deg (deg), scheme. --with-geometry draws dimensions reproducibly "
                    "(--seed) until one turns the crank fully (assembled, regular, no change point, every dyad's "
                    "transmission angle at least --min-transmission-angle, no group close to a singular "
                    "position). --out DIR writes mechanisms.csv, groups.csv (the catalogue of Assur groups), "
                    "chains.csv, a picture per mechanism (PNG: its graph and, with a geometry, its drawing) and a "
                    "scheme per mechanism that runs (loadable by 'linkage analyze', 'linkage enumerate').")
    p.add_argument("--links", "-n", metavar="N", type=whole(4, 12), required=True,
                   help="number of links: 4, 6, 8, 10 or 12 (12: 195816 mechanisms, about 7 minutes)")
    p.add_argument("--dof", metavar="W", type=int, default=1, help="degrees of freedom (only 1 is synthesized)")
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="write the tables, pictures and schemes into DIR (created)")
    p.add_argument("--with-geometry", action="store_true",
                   help="search a geometry that turns fully for every mechanism")
    p.add_argument("--seed", "-s", metavar="S", type=whole(0, 2**63 - 1), default=0,
                   help="seed of the geometry's draws (default 0; the same seed gives the same schemes)")
    p.add_argument("--draws", metavar="D", type=whole(1, 100_000), default=DEFAULT_DRAWS,
                   help=f"most draws of dimensions per mechanism (default {DEFAULT_DRAWS})")
    p.add_argument("--min-transmission-angle", metavar="DEG", type=float, default=DEFAULT_MIN_TRANSMISSION_DEG,
                   help="smallest transmission angle of every dyad over the turn, deg "
                        f"(default {DEFAULT_MIN_TRANSMISSION_DEG:g})")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", "-j", metavar="K", type=whole(1, 1024), default=1,
                       help="search the geometries in K worker processes (default 1)")
    where.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="search the geometries on a Dask distributed cluster at ADDRESS (tcp://host:8786); "
                            "needs the 'dask' extra: pip install \"linkage[dask]\"")
    add_format_argument(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    if args.dof != 1:
        raise InputError(f"--dof {args.dof}: only 1-DOF chains are synthesized (give --dof 1 or leave it out)")
    if args.links not in LINKS:
        raise InputError(f"--links {args.links}: 1-DOF chains of revolute pairs have an even number of links, "
                         f"3(n - 1) - 2p = 1: give one of {', '.join(map(str, LINKS))}")
    if not 0.0 < args.min_transmission_angle < 90.0:
        raise InputError(f"--min-transmission-angle {args.min_transmission_angle:g}: give an angle in (0, 90) deg")
    started = time.perf_counter()
    chain_list = chains(args.links)
    found = mechanisms(args.links, chain_list=chain_list, progress=progress("decomposing chains"))
    inversions = len({(t.chain, t.frame) for t in found})
    structure_seconds = time.perf_counter() - started
    results = None
    if args.with_geometry:
        results = search_all(found, args.seed, draws=args.draws, min_transmission_angle_deg=args.min_transmission_angle,
                             workers=args.workers, scheduler=args.scheduler, progress=progress("searching geometries"))
    counts = {"links": args.links, "chains": len(chain_list), "inversions": inversions, "mechanisms": len(found)}
    if results is not None:
        counts["with_geometry"] = sum(r.found for r in results)
        counts["without_geometry"] = len(results) - counts["with_geometry"]
    groups = catalogue(found)
    if args.out is not None:
        write_atlas(args.out, chain_list, found, results, seed=args.seed)
    columns = _columns(found, results)
    meta = {"counts": counts, "seconds": {"structure": round(structure_seconds, 3),
                                          "total": round(time.perf_counter() - started, 3)}}
    if args.format == "json":
        doc = {**meta,
               "chains": [{"name": c.name, "label": c.label, "assortment": list(c.assortment),
                           "edges": [list(e) for e in c.edges]} for c in chain_list],
               "groups": [vars(g) for g in groups],
               "mechanisms": [{k: _plain(v[i]) for k, v in columns.items()} for i in range(len(found))]}
        out(json.dumps(doc, ensure_ascii=False, allow_nan=False))
        return 0
    if args.format == "table":
        columns.pop("chain_label", None)
        columns.pop("scheme", None)
    out(format_columns(columns, args.format).rstrip("\n"))
    if args.format == "table":
        searched = "" if results is None else (f"; {counts['with_geometry']} with a geometry that turns fully, "
                                               f"{counts['without_geometry']} without one in {args.draws} draws")
        out(f"{args.links} links: {counts['chains']} chains, {inversions} inversions, {len(found)} mechanisms{searched}")
        out("Assur groups: " + "; ".join(f"{g.kind} class {g.group_class} ({g.links} links, {g.pairs} pairs) in "
                                         f"{g.mechanisms} mechanisms" for g in groups))
    if results is not None and counts["without_geometry"]:
        note("note", f"{counts['without_geometry']} of {len(found)} mechanisms got no geometry that turns fully "
                     f"in {args.draws} draws (more with --draws)")
    return 0


def progress(what: str):
    """A progress bar on stderr (tqdm, when installed and stderr is a terminal): ``bar(iterable, total)``."""
    def bar(iterable, total=None):
        try:
            from tqdm import tqdm
        except ImportError:  # the bar is a nicety of the report extra
            return iterable
        return tqdm(iterable, total=total, desc=f"{PROG}: {what}", file=sys.stderr, disable=None, leave=False,
                    delay=1.0)
    return bar


def _plain(value):
    """A table cell as a JSON value (NaN -> None, numpy numbers -> Python)."""
    if isinstance(value, (float, np.floating)):
        return None if np.isnan(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    return value


def _columns(found, results) -> dict[str, np.ndarray]:
    """The table: one row per mechanism."""
    def texts(values) -> np.ndarray:
        return np.array(list(values), dtype=object)

    columns = {
        "mechanism": texts(t.id for t in found),
        "chain": texts(t.chain for t in found),
        "chain_label": texts(t.chain_label or "" for t in found),
        "inversion": np.array([t.inversion for t in found], dtype=int),
        "frame": np.array([t.frame for t in found], dtype=int),
        "crank": np.array([t.crank for t in found], dtype=int),
        "formula": texts(t.formula for t in found),
        "class": texts(t.mechanism_class for t in found),
    }
    if results is not None:
        columns["geometry"] = texts("yes" if r.found else "no" for r in results)
        columns["draws"] = np.array([r.draws for r in results], dtype=int)
        columns["min_transmission_angle_deg"] = np.array(
            [np.nan if r.min_transmission_angle_deg is None else r.min_transmission_angle_deg for r in results])
        columns["scheme"] = texts(f"{r.id}.toml" if r.found else "" for r in results)
    return columns
