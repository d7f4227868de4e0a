"""The 1-DOF planar chains of :mod:`linkage.research.chains` against the literature and networkx.

Oracles: the classical counts of 1-DOF simple-jointed chains with no rigid sub-chain (1, 2, 16,
230, 6856 for 4 .. 12 links: Tsai, *Mechanism Design: Enumeration of Kinematic Structures
According to Function*, 2001; Mruthyunjaya 2003), and of their inversions (2 + 3 = 5 for six
links; 71 for eight, 1834 for ten, Tsai's tables); Chebyshev's count; rigidity counted here subset
by subset with itertools; isomorphism, automorphisms and orbits computed here with networkx's VF2
matcher (no igraph), so the canonical forms and orbits from igraph are checked by another library.
"""

from __future__ import annotations

import itertools
import random
import importlib
import sys

import networkx as nx
import pytest
from networkx.algorithms.isomorphism import GraphMatcher

from linkage.errors import InputError, LinkageError
from linkage.research.chains import (
    SynthesisExtraMissing,
    canonical_form,
    chains,
    input_choices,
    inversions,
    rigid_subchain,
)

pytest.importorskip("igraph", reason="the chains need the synthesis extra (igraph): pip install \".[synthesis]\"")

#: links -> chains, from the literature
COUNTS = {4: 1, 6: 2, 8: 16, 10: 230}
#: links -> inversions (frame choices) summed over the chains, from the literature
INVERSIONS = {4: 1, 6: 5, 8: 71, 10: 1834}


def automorphisms(graph: nx.Graph) -> list[dict]:
    """Every automorphism of ``graph`` by VF2 (networkx), as node -> node maps."""
    return list(GraphMatcher(graph, graph).isomorphisms_iter())


def orbits(graph: nx.Graph, fixed=None) -> list[set]:
    """The orbits of the nodes under the automorphisms (those keeping ``fixed`` if given)."""
    maps = [m for m in automorphisms(graph) if fixed is None or m[fixed] == fixed]
    found: list[set] = []
    for node in sorted(graph):
        if not any(node in orbit for orbit in found):
            found.append({m[node] for m in maps})
    return found


def is_rigid_somewhere(graph: nx.Graph) -> bool:
    """Some set of k >= 2 links with e pairs among them has 3(k - 1) - 2e <= 0 (itertools)."""
    nodes = list(graph)
    for k in range(2, len(nodes) + 1):
        for subset in itertools.combinations(nodes, k):
            if 3 * (k - 1) - 2 * graph.subgraph(subset).number_of_edges() <= 0:
                return True
    return False


@pytest.mark.parametrize("links", sorted(COUNTS))
def test_counts_agree_with_the_literature(links):
    found = chains(links)
    assert len(found) == COUNTS[links]
    assert sum(len(inversions(chain)) for chain in found) == INVERSIONS[links]


def test_twelve_link_chains_number_6856():
    """About five seconds here (see docs/synthesis.md for the times measured)."""
    found = chains(12)
    assert len(found) == 6856
    assert len({chain.edges for chain in found}) == 6856
    assert all(len(chain.edges) == 16 for chain in found)


@pytest.mark.parametrize("links", sorted(COUNTS))
def test_every_chain_is_a_sound_one_dof_chain(links):
    for chain in chains(links):
        graph = chain.graph
        assert sorted(graph) == list(range(links))
        assert graph.number_of_edges() == len(chain.edges) == (3 * links - 4) // 2
        assert 3 * (links - 1) - 2 * len(chain.edges) == 1                       # Chebyshev
        assert nx.is_biconnected(graph) and min(d for _, d in graph.degree) >= 2
        assert rigid_subchain(graph) is None
        degrees = [d for _, d in graph.degree]
        assert chain.assortment == tuple(degrees.count(k) for k in range(2, max(degrees) + 1))
        assert all(a < b for a, b in chain.edges) and list(chain.edges) == sorted(chain.edges)


def test_no_rigid_subchain_counted_subset_by_subset():
    for chain in chains(6) + chains(8):
        assert not is_rigid_somewhere(chain.graph)


@pytest.mark.parametrize("links", [6, 8, 10])
def test_chains_are_pairwise_non_isomorphic(links):
    found = chains(links)
    by_degrees: dict[tuple, list[nx.Graph]] = {}       # only graphs of one degree sequence can be isomorphic
    for chain in found:
        by_degrees.setdefault(tuple(sorted(d for _, d in chain.graph.degree)), []).append(chain.graph)
    for graphs in by_degrees.values():
        for g, h in itertools.combinations(graphs, 2):
            assert not nx.is_isomorphic(g, h)


@pytest.mark.parametrize("links", [4, 6, 8, 10])
def test_names_are_in_order_and_unique(links):
    found = chains(links)
    width = len(str(len(found)))
    assert [chain.name for chain in found] == [f"{links}.{k:0{width}d}" for k in range(1, len(found) + 1)]
    assert chains(links) == found                                                  # deterministic


def test_six_link_chains_are_watt_and_stephenson():
    watt, stephenson = chains(6)
    for chain, adjacent in ((watt, True), (stephenson, False)):
        ternary = [node for node, degree in chain.graph.degree if degree == 3]
        assert len(ternary) == 2 and chain.graph.has_edge(*ternary) == adjacent
    assert (watt.label, stephenson.label) == ("Watt", "Stephenson")
    assert [len(inversions(watt)), len(inversions(stephenson))] == [2, 3]          # Watt I, II; Stephenson I-III
    assert (watt.automorphisms, stephenson.automorphisms) == (4, 4)


def test_four_bar():
    (four_bar,) = chains(4)
    assert four_bar.label == "four-bar" and four_bar.assortment == (4,) and four_bar.automorphisms == 8
    assert nx.is_isomorphic(four_bar.graph, nx.cycle_graph(4))
    assert inversions(four_bar) == [0]
    assert len(input_choices(four_bar, 0)) == 1


@pytest.mark.parametrize("links", [6, 8])
def test_orbits_agree_with_networkx(links):
    for chain in chains(links):
        graph = chain.graph
        assert chain.automorphisms == len(automorphisms(graph))
        frame_orbits = orbits(graph)
        frames = inversions(chain)
        assert len(frames) == len(frame_orbits)
        assert all(sum(frame in orbit for frame in frames) == 1 for orbit in frame_orbits)
        for frame in frames:
            near = set(graph[frame])
            crank_orbits = [orbit & near for orbit in orbits(graph, fixed=frame) if orbit & near]
            cranks = input_choices(chain, frame)
            assert set(cranks) <= near and len(cranks) == len(crank_orbits)
            assert all(sum(crank in orbit for crank in cranks) == 1 for orbit in crank_orbits)


def test_relabellings_have_one_canonical_form():
    shuffle = random.Random(25)
    for chain in chains(8) + chains(10)[::10]:
        forms = set()
        for _ in range(5):
            names = list(range(chain.links))
            shuffle.shuffle(names)
            relabelled = nx.relabel_nodes(chain.graph, {k: f"link {names[k]}" for k in range(chain.links)})
            forms.add(canonical_form(relabelled))
        assert forms == {chain.edges}


def test_canonical_form_tells_watt_from_stephenson():
    watt = nx.Graph([(0, 1), (0, 2), (2, 3), (3, 1), (0, 4), (4, 5), (5, 1)])
    stephenson = nx.Graph([(0, 2), (2, 1), (0, 3), (3, 1), (0, 4), (4, 5), (5, 1)])
    assert canonical_form(watt) != canonical_form(stephenson)
    assert {canonical_form(watt), canonical_form(stephenson)} == {chain.edges for chain in chains(6)}


def test_rigid_subchain_finds_the_smallest():
    assert rigid_subchain(nx.cycle_graph(3)) == (0, 1, 2)                           # a triangle: 3*2 - 2*3 = 0
    # a five-link loop with a chord a-c: the triangle a, b, c is rigid (so is the whole, 3*4 - 2*6 = 0)
    graph = nx.Graph([("a", "b"), ("b", "c"), ("c", "d"), ("d", "e"), ("e", "a"), ("a", "c")])
    assert rigid_subchain(graph) == ("a", "b", "c")
    assert rigid_subchain(nx.cycle_graph(5)) is None
    assert rigid_subchain(nx.MultiGraph([(0, 1), (0, 1)])) == (0, 1)               # two pairs: 3 - 4 < 0
    with pytest.raises(InputError, match="self-loop"):
        rigid_subchain(nx.Graph([(0, 0), (0, 1)]))


@pytest.mark.parametrize("links", [0, 3, 5, 7, 14, 4.0, True, "8"])
def test_numbers_of_links_without_chains_are_refused(links):
    with pytest.raises(InputError, match="4, 6, 8, 10 or 12"):
        chains(links)


def test_bad_frame_is_refused():
    with pytest.raises(InputError, match="frame link 9"):
        input_choices(chains(6)[0], 9)


def test_progress_is_called_per_assortment():
    module = importlib.import_module("linkage.research.chains")   # the package exports the function `chains`

    calls = []
    fresh = module._enumerate(8, lambda done, total: calls.append((done, total)))
    assert fresh == tuple(chains(8))
    # 8 links, 10 pairs: n3 + 2 n4 + 3 n5 + 4 n6 = 2*10 - 2*8 = 4 has 5 solutions
    assert calls == [(k, 5) for k in range(1, 6)]


def test_without_igraph_the_hint_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "igraph", None)
    with pytest.raises(SynthesisExtraMissing, match=r'pip install "linkage\[synthesis\]"') as caught:
        chains(6)
    assert isinstance(caught.value, LinkageError) and isinstance(caught.value, ImportError)


# -- pictures ---------------------------------------------------------------------------------------

def _segments_cross(p, q, r, s) -> bool:
    def side(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return side(p, q, r) * side(p, q, s) < 0 and side(r, s, p) * side(r, s, q) < 0


def test_eight_link_layouts_have_no_crossing_and_no_overlap():
    """Every eight-link chain is planar (networkx says so); its drawing has no two pairs crossing
    and no two links at one place, checked here segment by segment."""
    from linkage.report.chain_pictures import chain_layout

    for chain in chains(8):
        assert nx.check_planarity(chain.graph)[0]
        positions = chain_layout(chain)
        assert sorted(positions) == list(range(8))
        for (a, b), (c, d) in itertools.combinations(chain.edges, 2):
            if len({a, b, c, d}) == 4:
                assert not _segments_cross(positions[a], positions[b], positions[c], positions[d]), chain.name
        points = [positions[k] for k in range(8)]
        size = max(max(p[0] for p in points) - min(p[0] for p in points), max(p[1] for p in points) - min(p[1] for p in points))
        assert min(((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2) ** 0.5 for p, q in itertools.combinations(points, 2)) > 0.03 * size


def test_grid_picture_names_every_chain(tmp_path):
    matplotlib = pytest.importorskip("matplotlib", reason="pictures need the plot extra (matplotlib)")
    matplotlib.use("Agg")
    from linkage.report.chain_pictures import draw_chain, draw_chains

    figure = draw_chains(chains(8), columns=4)
    titles = [ax.get_title() for ax in figure.axes if ax.get_title()]
    assert [title.split("\n")[0] for title in titles] == [f"8.{k:02d}" for k in range(1, 17)]
    assert titles[0].split("\n")[1] == "(" + ", ".join(map(str, chains(8)[0].assortment)) + ")"
    legend = [text.get_text() for text in figure.legends[0].get_texts()]
    assert legend == ["binary link", "ternary link", "quaternary link", "revolute pair"]
    figure.savefig(tmp_path / "chains.png", dpi=60)
    assert (tmp_path / "chains.png").stat().st_size > 10_000
    matplotlib.pyplot.close(figure)
    watt = chains(6)[0]
    ax = draw_chain(watt, frame=0, crank=next(iter(watt.graph[0])), numbers=True)
    assert ax.get_title().startswith("6.1 Watt")
    with pytest.raises(InputError, match="not paired with the frame"):
        draw_chain(watt, frame=0, crank=next(k for k in range(6) if k != 0 and not watt.graph.has_edge(0, k)))
    matplotlib.pyplot.close("all")
