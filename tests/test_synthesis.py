"""Structural synthesis: the mechanisms of the 1-DOF chains, their groups, and geometries that run.

Oracles: the literature's counts of inversions (Watt 2 + Stephenson 3 = 5 for six links, 71 for
eight; Tsai, Mechanism Design: Enumeration of Kinematic Structures, 2001); the number of
(frame, crank) choices modulo each chain's symmetry counted here by brute force over networkx's
automorphisms (independent of igraph); Chebyshev's count for each group (3 n = 2 p) and for the
whole mechanism; the decomposition of the built mechanism by :func:`linkage.structure.decompose`;
the written schemes' pair closure computed here from the link poses and local points.
"""

from __future__ import annotations

import json

import networkx as nx
import numpy as np
import pytest
from networkx.algorithms.isomorphism import GraphMatcher

import linkage
from linkage.kinematics.full_turn import input_cannot_turn
from linkage.research.chains import chains
from linkage.research.synthesis import catalogue, mechanisms
from linkage.research.synthesis_geometry import (
    _draw,
    _rng,
    _source,
    search_all,
    search_geometry,
)
from linkage.structure import MAX_GROUP_LINKS, decompose

pytest.importorskip("igraph", reason="structural synthesis needs the synthesis extra (igraph): pip install \".[synthesis]\"")


def _choices_by_brute_force(chain) -> tuple[int, int]:
    """(inversions, mechanisms) of a chain: orbits of the frame and of the ordered (frame, crank)
    pairs of adjacent links under every automorphism networkx finds."""
    graph = chain.graph
    autos = list(GraphMatcher(graph, graph).isomorphisms_iter())
    frames = {min(a[k] for a in autos) for k in graph}
    pairs = {min((a[f], a[c]) for a in autos) for f, c in [*graph.edges, *((b, a) for a, b in graph.edges)]}
    return len(frames), len(pairs)


@pytest.mark.parametrize("links, inversions", [(4, 1), (6, 5), (8, 71), (10, None)])
def test_inversions_and_mechanisms_match_the_literature_and_brute_force(links, inversions):
    found = mechanisms(links)
    brute = [_choices_by_brute_force(c) for c in chains(links)]
    assert len({(t.chain, t.frame) for t in found}) == sum(b[0] for b in brute) == (inversions or sum(b[0] for b in brute))
    assert len(found) == sum(b[1] for b in brute)
    assert len({t.id for t in found}) == len(found)


def test_six_link_mechanisms_watt_two_dyads_stephenson_has_a_triad_and_a_tetrad():
    found = mechanisms(6)
    watt = [t for t in found if t.chain_label == "Watt"]
    stephenson = [t for t in found if t.chain_label == "Stephenson"]
    assert len({t.frame for t in watt}) == 2 and len({t.frame for t in stephenson}) == 3
    # the Watt chain's two four-bar loops always split into two dyads, whatever the frame and crank
    assert all([len(g.links) for g in t.groups] == [2, 2] for t in watt)
    classes = {t.mechanism_class for t in stephenson}
    assert classes == {"II", "III", "IV"}
    assert linkage.load("four_bar") and mechanisms(4)[0].formula == "I(0,1) → II-RRR(2,3)"


@pytest.mark.parametrize("links", [6, 8])
def test_every_group_is_statically_determinate_and_the_formula_re_decomposes(links):
    for t in mechanisms(links):
        assert sum(len(g.links) for g in t.groups) == links - 2
        assert sum(g.pairs for g in t.groups) == 3 * (links - 2) // 2        # p - 1 pairs outside the crank
        assert all(3 * len(g.links) == 2 * g.pairs for g in t.groups)
        source, _ = _source(t, *_draw(t, _rng(0, t.id)))
        if max(len(g.links) for g in t.groups) <= MAX_GROUP_LINKS:
            assert decompose(source).formula == t.formula, t.id
        assert t.mechanism_class == max((g.group_class for g in t.groups), key=lambda c: len(c) if "V" not in c
                                        else {"IV": 4, "V": 5, "VI": 6}[c])


def test_catalogue_counts_the_mechanisms_of_each_group():
    found = mechanisms(8)
    table = {(g.links, g.pairs, g.group_class): g for g in catalogue(found)}
    dyads = table[(2, 3, "II")]
    assert dyads.mechanisms == sum(any(len(g.links) == 2 for g in t.groups) for t in found)
    assert sum(g.occurrences for g in table.values()) == sum(len(t.groups) for t in found)
    assert {(4, 6, "III"), (4, 6, "IV")} <= set(table)


def _closure(mech, motion) -> float:
    """Largest gap of any revolute pair's two points over the motion, m."""
    worst = 0.0
    for pair in mech.pairs.values():
        ends = []
        for link in pair.links:
            x, y, theta = (motion.poses[link][:, i] for i in range(3))
            px, py = mech.links[link].points[pair.point]
            ends.append(np.stack([x + np.cos(theta) * px - np.sin(theta) * py,
                                  y + np.sin(theta) * px + np.cos(theta) * py], axis=1))
        worst = max(worst, float(np.max(np.linalg.norm(ends[0] - ends[1], axis=1))))
    return worst


def test_six_link_geometries_load_turn_fully_and_close(tmp_path):
    found = mechanisms(6)
    picked = [t for t in found if t.mechanism_class in ("III", "IV")] + [found[0]]
    for t in picked:
        result = search_geometry(t, seed=3)
        assert result.found, result.note
        path = tmp_path / f"{t.id}.toml"
        path.write_text(result.scheme)
        mech = linkage.load(path)
        assert input_cannot_turn(mech) is None
        motion = linkage.analyze(mech, np.radians(np.arange(360.0)))
        assert np.all(motion.status >= 0)
        assert _closure(mech, motion) <= 1e-9 * mech.size
        assert linkage.structure.structure_of(mech).formula == t.formula
        assert search_geometry(t, seed=3).scheme == result.scheme          # reproducible


def test_an_eight_link_mechanism_of_one_six_link_group_loads_turns_fully_and_closes(tmp_path):
    """8.15 with link 4 as the frame and 0 as the crank: one class-V group of six links, solved by
    Newton's method (decompose searches groups of up to MAX_GROUP_LINKS = 10 links)."""
    (t,) = [t for t in mechanisms(8) if t.id == "8.15-f4-c0"]
    assert [len(g.links) for g in t.groups] == [6] and MAX_GROUP_LINKS >= 6
    result = search_geometry(t, seed=0)
    assert result.found, result.note
    path = tmp_path / f"{t.id}.toml"
    path.write_text(result.scheme)
    mech = linkage.load(path)
    assert linkage.structure.structure_of(mech).formula == t.formula
    motion = linkage.analyze(mech, np.radians(np.arange(0.0, 360.0, 2.0)))
    assert np.all(motion.status == 0)
    assert _closure(mech, motion) <= 1e-9 * mech.size


def test_workers_give_the_same_schemes():
    found = mechanisms(6)[:3]
    assert [r.scheme for r in search_all(found, 5, workers=2)] == [r.scheme for r in search_all(found, 5)]


def test_cli_counts_and_refusals(linkage_run):
    doc = json.loads(linkage_run("synthesize", "--links", "6", "--format", "json").out)
    brute = [_choices_by_brute_force(c) for c in chains(6)]
    assert doc["counts"]["chains"] == 2
    assert doc["counts"]["inversions"] == sum(b[0] for b in brute) == 5
    assert doc["counts"]["mechanisms"] == sum(b[1] for b in brute)
    assert all(isinstance(doc["counts"][k], int) for k in ("chains", "inversions", "mechanisms"))
    bad = linkage_run("synthesize", "--links", "6", "--dof", "2")
    assert bad.status == 2 and "--dof 2" in bad.err
    odd = linkage_run("synthesize", "--links", "7")
    assert odd.status == 2 and "even number of links" in odd.err


def test_cli_writes_an_atlas(linkage_run, tmp_path):
    out = tmp_path / "atlas"
    doc = json.loads(linkage_run("synthesize", "--links", "4", "--with-geometry", "--out", str(out),
                                 "--format", "json").out)
    assert doc["counts"]["mechanisms"] == 1 and doc["counts"]["with_geometry"] == 1
    (row,) = doc["mechanisms"]
    mech = linkage.load(out / row["scheme"])
    assert input_cannot_turn(mech) is None
    assert row["min_transmission_angle_deg"] >= 20.0
    assert (out / f"{row['mechanism']}.png").stat().st_size > 1000
    assert nx.is_connected(chains(4)[0].graph)
