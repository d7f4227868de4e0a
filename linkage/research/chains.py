"""Planar kinematic chains of one degree of freedom, and their symmetry.

A chain with revolute pairs is a graph: its links are vertices, its pairs edges. Chebyshev's count
for one degree of freedom, ``3(n - 1) - 2p = 1``, allows n = 4, 6, 8, 10, 12 links with
p = (3n - 4)/2 = 4, 7, 10, 13, 16 pairs. :func:`chains` lists every non-isomorphic such chain with
no rigid sub-chain (docs/synthesis.md), by the classical route:

1. *link assortments*: the numbers ``(n2, n3, ...)`` of binary, ternary ... links with
   ``sum n_k = n`` and ``sum k n_k = 2p``;
2. *contracted graphs*: loopless connected multigraphs on the non-binary links, with their
   degrees; each edge stands for a string of binary links (possibly none) between two of them;
3. the binary links distributed over the edges in every way; a distribution is kept when no
   sub-chain is rigid, read on the contracted graph: for a set T of non-binary links and the
   strings between them taken whole, the mobility is ``3(|T| - 1) + sum (j - 2)`` over strings
   of j binary links, so a chain is rigid somewhere iff ``3(|T| - 1) + sum min(0, j - 2) <= 0``
   for some T with two links or more (a string taken in part, or a link hanging by one pair, only
   adds mobility). Two pairs between the same two links are a rigid sub-chain by that rule, so
   every kept chain is a simple graph, and connected and 2-connected (a cut would split the one
   degree of freedom into two parts, one of them of mobility <= 0);
4. the chains kept are told apart by the canonical labelling of igraph (bliss,
   :func:`canonical_form`), the contracted multigraphs too (each edge subdivided by a vertex of
   its own colour).

The counts are 1, 2, 16, 230 and 6856 for 4, 6, 8, 10, 12 links (Tsai, *Mechanism Design:
Enumeration of Kinematic Structures According to Function*, 2001, ch. 4; Mruthyunjaya 2003).
:func:`inversions` gives one frame link per orbit of a chain's automorphism group,
:func:`input_choices` one crank per orbit of the frame's stabiliser among the links next to the
frame; :func:`rigid_subchain` checks a graph subset by subset, independently of the method above.

igraph is optional (the ``synthesis`` extra): without it these functions raise
:class:`SynthesisExtraMissing`.

>>> [len(chains(n)) for n in (4, 6, 8)]
[1, 2, 16]
>>> [(c.name, c.label, c.assortment) for c in chains(6)]
[('6.1', 'Watt', (4, 2)), ('6.2', 'Stephenson', (4, 2))]
>>> [sorted(len(input_choices(chain, frame)) for frame in inversions(chain)) for chain in chains(6)]
[[2, 2], [1, 2, 2]]
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, LinkageError

__all__ = ["CHAIN_LINKS", "INSTALL_HINT", "Chain", "SynthesisExtraMissing", "canonical_form", "chains",
           "input_choices", "inversions", "link_orbits", "rigid_subchain"]

#: what to install for structural synthesis
INSTALL_HINT = 'structural synthesis needs igraph, the optional "synthesis" extra: pip install "linkage[synthesis]"'

#: the numbers of links a 1-DOF planar chain with revolute pairs can have (here, up to 12)
CHAIN_LINKS = (4, 6, 8, 10, 12)

#: the names of the chains that have one
_LABELS = {4: "four-bar"}


class SynthesisExtraMissing(LinkageError, ImportError):
    """igraph is not installed: structural synthesis needs ``pip install "linkage[synthesis]"``."""


def _igraph():
    """The ``igraph`` module, or :class:`SynthesisExtraMissing` with the install hint."""
    try:
        import igraph
    except ImportError as exc:
        raise SynthesisExtraMissing(INSTALL_HINT) from exc
    return igraph


@dataclass(frozen=True)
class Chain:
    """A planar kinematic chain of revolute pairs, in its canonical labelling.

    Attributes
    ----------
    links : int
        Number of links n; they are numbered 0 .. n-1.
    edges : tuple of (int, int)
        The pairs, each ``(a, b)`` with ``a < b``, sorted; the labelling is igraph's canonical one
        (:func:`canonical_form`), so two isomorphic chains have the same edges.
    name : str
        ``"<n>.<k>"``: n links and the chain's 1-based place in :func:`chains`' order, e.g. ``"8.07"``.
    assortment : tuple of int
        Numbers of binary, ternary, quaternary ... links (up to the highest present).
    label : str or None
        The chain's classical name where it has one (``"four-bar"``, ``"Watt"``, ``"Stephenson"``).
    """

    links: int
    edges: tuple[tuple[int, int], ...]
    name: str
    assortment: tuple[int, ...]
    label: str | None = None

    @property
    def pairs(self) -> int:
        """Number of revolute pairs p."""
        return len(self.edges)

    @property
    def degrees(self) -> tuple[int, ...]:
        """Number of pairs on each link, by link number."""
        counts = np.bincount(np.asarray(self.edges, dtype=int).ravel(), minlength=self.links)
        return tuple(int(k) for k in counts)

    @property
    def graph(self):
        """The chain as a ``networkx.Graph``: nodes 0 .. n-1 (links), edges the pairs."""
        import networkx as nx

        graph = nx.Graph()
        graph.add_nodes_from(range(self.links))
        graph.add_edges_from(self.edges)
        return graph

    @property
    def automorphisms(self) -> int:
        """Order of the chain's automorphism group (the relabellings that keep every pair)."""
        graph = _igraph().Graph(n=self.links, edges=list(self.edges))
        return int(graph.count_automorphisms())


# ---------------------------------------------------------------------------------------------
# canonical forms, orbits, rigidity
# ---------------------------------------------------------------------------------------------

def _indexed(graph) -> tuple[list, list[tuple[int, int]]]:
    """The nodes of a networkx graph in sorted order and its edges as index pairs (no self-loop)."""
    try:
        nodes = sorted(graph.nodes)
    except TypeError:
        nodes = list(graph.nodes)
    index = {node: k for k, node in enumerate(nodes)}
    edges = [(index[a], index[b]) for a, b in graph.edges()]
    loops = [nodes[a] for a, b in edges if a == b]
    if loops:
        raise InputError(f"a kinematic chain has no pair of a link with itself: self-loop at link {loops[0]!r}")
    return nodes, edges


def _canonical_edges(links: int, edges: Iterable[tuple[int, int]]) -> tuple[tuple[int, int], ...]:
    """The sorted edges of a simple graph on 0 .. links-1 after igraph's canonical permutation."""
    edges = list(edges)
    graph = _igraph().Graph(n=links, edges=edges)
    return _sorted_edges(graph.permute_vertices(graph.canonical_permutation()))


def _sorted_edges(graph) -> tuple[tuple[int, int], ...]:
    """The edges of an igraph graph as sorted ``(a, b)``, ``a < b``."""
    return tuple(sorted((min(a, b), max(a, b)) for a, b in graph.get_edgelist()))


def canonical_form(graph) -> tuple[tuple[int, int], ...]:
    """The edges of ``graph`` in igraph's canonical labelling (bliss): a certificate of isomorphism.

    Parameters
    ----------
    graph : networkx.Graph
        Any simple graph (the links of a chain as nodes, of any hashable labels).

    Returns
    -------
    tuple of (int, int)
        The edges ``(a, b)``, ``a < b``, sorted, on the nodes renumbered 0 .. n-1 canonically:
        two graphs give the same tuple if and only if they are isomorphic (and have as many nodes).

    >>> import networkx as nx
    >>> canonical_form(nx.cycle_graph(4)) == canonical_form(nx.relabel_nodes(nx.cycle_graph(4), {0: 2, 2: 0}))
    True
    """
    nodes, edges = _indexed(graph)
    if graph.is_multigraph() and len(set(map(frozenset, edges))) != len(edges):
        raise InputError("canonical_form takes a simple graph: two pairs join the same two links")
    return _canonical_edges(len(nodes), edges)


def _orbits(links: int, generators: list[list[int]]) -> list[list[int]]:
    """The orbits of the group generated by ``generators`` (permutations of 0 .. links-1), each
    sorted, ordered by their smallest link."""
    parent = list(range(links))

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for permutation in generators:
        for k, image in enumerate(permutation):
            a, b = root(k), root(image)
            if a != b:
                parent[max(a, b)] = min(a, b)
    groups: dict[int, list[int]] = {}
    for k in range(links):
        groups.setdefault(root(k), []).append(k)
    return sorted(groups.values())


def link_orbits(chain: Chain, fixed: int | None = None) -> list[list[int]]:
    """The orbits of the chain's links under its automorphisms (those fixing link ``fixed`` if given).

    Returns
    -------
    list of list of int
        Every link in exactly one orbit; each orbit sorted, the orbits by their smallest link.
    """
    colours = None
    if fixed is not None:
        _check_link(chain, fixed, "frame")
        colours = [int(k == fixed) for k in range(chain.links)]
    graph = _igraph().Graph(n=chain.links, edges=list(chain.edges))
    return _orbits(chain.links, graph.automorphism_group(color=colours))


def _check_link(chain: Chain, link: int, role: str) -> None:
    if not isinstance(link, (int, np.integer)) or not 0 <= link < chain.links:
        raise InputError(f"{role} link {link!r} is not a link of chain {chain.name} (links 0 .. {chain.links - 1})")


def inversions(chain: Chain) -> list[int]:
    """One frame link per inversion of ``chain``: the smallest link of each orbit of its automorphisms.

    The four-bar has one inversion, Watt's chain two, Stephenson's three.
    """
    return [orbit[0] for orbit in link_orbits(chain)]


def input_choices(chain: Chain, frame: int) -> list[int]:
    """The distinct cranks for a frame: one link per orbit, among the links paired with ``frame``,
    of the automorphisms that keep ``frame`` in place (the smallest link of each orbit)."""
    neighbours = {b if a == frame else a for a, b in chain.edges if frame in (a, b)}
    _check_link(chain, frame, "frame")
    return [min(set(orbit) & neighbours) for orbit in link_orbits(chain, frame) if set(orbit) & neighbours]


def rigid_subchain(graph) -> tuple | None:
    """A set of links with mobility ``3(k - 1) - 2e <= 0`` (k >= 2 links, e pairs among them), or None.

    Every subset of the links is counted (2**n of them, vectorised), the smallest rigid one is
    returned (fewest links, then the first in sorted order).

    Parameters
    ----------
    graph : networkx.Graph or networkx.MultiGraph
        Links as nodes, pairs as edges (a multiple pair counted as its several pairs).

    Returns
    -------
    tuple or None
        The nodes of a rigid sub-chain, or None if there is none.

    >>> import networkx as nx
    >>> rigid_subchain(nx.cycle_graph(4)) is None, rigid_subchain(nx.cycle_graph(3))
    (True, (0, 1, 2))
    """
    nodes, edges = _indexed(graph)
    links = len(nodes)
    if links < 2:
        return None
    if links > 24:
        raise InputError(f"rigid_subchain counts every subset: {links} links are too many (at most 24)")
    masks = np.arange(1 << links, dtype=np.int64)
    members = ((masks[:, None] >> np.arange(links)) & 1).astype(np.int8)     # (2**n, n)
    size = members.sum(axis=1, dtype=np.int64)
    pairs = np.zeros(masks.size, dtype=np.int64)
    for a, b in edges:
        pairs += members[:, a] & members[:, b]
    rigid = (size >= 2) & (3 * (size - 1) - 2 * pairs <= 0)
    if not rigid.any():
        return None
    candidates = masks[rigid]
    order = np.lexsort((candidates, size[rigid]))
    best = int(candidates[order[0]])
    return tuple(nodes[k] for k in range(links) if best >> k & 1)


# ---------------------------------------------------------------------------------------------
# the enumeration
# ---------------------------------------------------------------------------------------------

def _assortments(links: int, pairs: int) -> list[tuple[int, ...]]:
    """Every ``(n2, n3, ...)`` with sum n_k = links and sum k n_k = 2 pairs (no trailing zero),
    most binary links first."""
    excess = 2 * pairs - 2 * links        # sum (k - 2) n_k over the non-binary links
    found = []

    def extend(degree: int, left: int, counts: list[int]) -> None:
        if left == 0:
            non_binary = sum(counts)
            if non_binary <= links:
                found.append(tuple([links - non_binary] + counts))
            return
        if degree - 2 > left:
            return
        for count in range(left // (degree - 2), -1, -1):
            extend(degree + 1, left - count * (degree - 2), counts + [count])

    if excess == 0:
        return [(links,)]
    extend(3, excess, [])
    trimmed = set()
    for assortment in found:
        while assortment[-1] == 0:
            assortment = assortment[:-1]
        trimmed.add(assortment)
    return sorted(trimmed, reverse=True)


def _multigraphs(degrees: tuple[int, ...], binary: int) -> list[tuple[tuple[int, int], ...]]:
    """Every connected loopless multigraph with these vertex degrees that ``binary`` binary links
    can make rigid-free, one per isomorphism class, as its edge list (an edge repeated once per
    multiplicity).

    Two links joined by mu strings are rigid unless ``3 + sum min(0, j - 2) > 0`` over the strings
    (j binary links each): at most one empty string, or two of one link, the others of two or
    more, so those mu strings take ``2 (mu - 1)`` binary links at least; a multigraph needing more
    than ``binary`` is not built. Vertices of one degree can be renumbered among themselves, so
    only multigraphs whose first vertex's multiplicities are non-increasing along each run of
    vertices of one degree are built (each isomorphism class still has one)."""
    vertices = len(degrees)
    if vertices < 2:                                  # one link could only be paired with itself
        return []
    pairs = [(a, b) for a in range(vertices) for b in range(a + 1, vertices)]
    remaining = list(degrees)
    multiplicity = [0] * len(pairs)
    last_pair_of = {a: max(k for k, (x, y) in enumerate(pairs) if a in (x, y)) for a in range(vertices)}
    found: dict[tuple, tuple[tuple[int, int], ...]] = {}
    igraph = _igraph()

    def place(k: int, budget: int) -> None:
        if k == len(pairs):
            edges = [pair for pair, times in zip(pairs, multiplicity) for _ in range(times)]
            if not _connected(vertices, edges):
                return
            key = _multigraph_key(igraph, vertices, edges)
            found.setdefault(key, tuple(edges))
            return
        a, b = pairs[k]
        least, most = 0, min(remaining[a], remaining[b])
        for end in (a, b):
            if last_pair_of[end] == k:                  # the end's last pair: it takes what is left
                least = max(least, remaining[end])
                most = min(most, remaining[end])
        most = min(most, budget // 2 + 1)
        if a == 0 and b >= 2 and degrees[b] == degrees[b - 1]:
            most = min(most, multiplicity[k - 1])      # links of one degree: the first row non-increasing
        for times in range(least, most + 1):
            multiplicity[k] = times
            remaining[a] -= times
            remaining[b] -= times
            place(k + 1, budget - 2 * max(times - 1, 0))
            remaining[a] += times
            remaining[b] += times
        multiplicity[k] = 0

    place(0, binary)
    return [found[key] for key in sorted(found)]


def _connected(vertices: int, edges: list[tuple[int, int]]) -> bool:
    """Whether the graph on 0 .. vertices-1 with these edges is connected."""
    reached = {0}
    frontier = [0]
    neighbours: dict[int, list[int]] = {k: [] for k in range(vertices)}
    for a, b in edges:
        neighbours[a].append(b)
        neighbours[b].append(a)
    while frontier:
        for other in neighbours[frontier.pop()]:
            if other not in reached:
                reached.add(other)
                frontier.append(other)
    return len(reached) == vertices


def _multigraph_key(igraph, vertices: int, edges: list[tuple[int, int]]) -> tuple:
    """A canonical form of a multigraph: each edge subdivided by a vertex of a second colour."""
    subdivided = []
    for k, (a, b) in enumerate(edges):
        subdivided += [(a, vertices + k), (b, vertices + k)]
    colours = [0] * vertices + [1] * len(edges)
    total = vertices + len(edges)
    graph = igraph.Graph(n=total, edges=subdivided)
    return _sorted_edges(graph.permute_vertices(graph.canonical_permutation(color=colours)))


def _compositions(total: int, parts: int) -> np.ndarray:
    """Every way to write ``total`` as an ordered sum of ``parts`` non-negative integers, (count, parts)."""
    rows = []
    for bars in itertools.combinations(range(total + parts - 1), parts - 1):
        edges = (-1,) + bars + (total + parts - 1,)
        rows.append([edges[k + 1] - edges[k] - 1 for k in range(parts)])
    return np.asarray(rows, dtype=np.int64).reshape(-1, parts)


def _distributions(edges: tuple[tuple[int, int], ...], vertices: int, binary: int) -> np.ndarray:
    """The numbers of binary links on each contracted edge that leave no rigid sub-chain, (count, edges)."""
    strings = _compositions(binary, len(edges))
    subsets = np.arange(1 << vertices, dtype=np.int64)
    members = (subsets[:, None] >> np.arange(vertices)) & 1                         # (2**m, m)
    size = members.sum(axis=1)
    ends = np.asarray(edges, dtype=np.int64)
    inside = members[:, ends[:, 0]] & members[:, ends[:, 1]]                       # (2**m, E)
    keep = size >= 2
    # least mobility of each vertex subset for each distribution: 3(|T| - 1) + sum min(0, j - 2)
    mobility = 3 * (size[keep] - 1)[None, :] + np.minimum(strings - 2, 0) @ inside[keep].T
    return strings[(mobility > 0).all(axis=1)]


def _chain_edges(edges: tuple[tuple[int, int], ...], vertices: int, strings: np.ndarray) -> list[tuple[int, int]]:
    """The pairs of the chain whose contracted edges carry ``strings`` binary links each."""
    pairs = []
    link = vertices
    for (a, b), count in zip(edges, strings.tolist()):
        path = [a] + list(range(link, link + count)) + [b]
        link += count
        pairs += list(itertools.pairwise(path))
    return pairs


def _invariant(links: int, edges: tuple[tuple[int, int], ...]) -> tuple:
    """An order key of a chain that does not depend on the labelling: the degree of each link with
    the sorted degrees of its neighbours, sorted (highest first)."""
    neighbours: dict[int, list[int]] = {k: [] for k in range(links)}
    for a, b in edges:
        neighbours[a].append(b)
        neighbours[b].append(a)
    return tuple(sorted(((len(near), tuple(sorted((len(neighbours[j]) for j in near), reverse=True)))
                         for near in neighbours.values()), reverse=True))


def _label(links: int, assortment: tuple[int, ...], edges: tuple[tuple[int, int], ...]) -> str | None:
    if links in _LABELS:
        return _LABELS[links]
    if links == 6:
        ternary = [k for k in range(links) if sum(k in edge for edge in edges) == 3]
        return "Watt" if tuple(ternary) in edges else "Stephenson"
    return None


def _enumerate(links: int, progress: Callable[[int, int], None] | None) -> tuple[Chain, ...]:
    """The chains of ``links`` links (the work of :func:`chains`, uncached)."""
    pairs = (3 * links - 4) // 2
    found: dict[tuple, tuple[int, ...]] = {}
    assortments = _assortments(links, pairs)
    for done, assortment in enumerate(assortments, start=1):
        binary = assortment[0]
        degrees = tuple(degree for degree in range(len(assortment) + 1, 2, -1)
                        for _ in range(assortment[degree - 2]))
        if not degrees:                                     # only binary links: a closed loop
            if links == pairs:
                cycle = [(k, (k + 1) % links) for k in range(links)]
                found.setdefault(_canonical_edges(links, cycle), assortment)
        else:
            for contracted in _multigraphs(degrees, binary):
                for strings in _distributions(contracted, len(degrees), binary):
                    chain_edges = _chain_edges(contracted, len(degrees), strings)
                    found.setdefault(_canonical_edges(links, chain_edges), assortment)
        if progress is not None:
            progress(done, len(assortments))
    ordered = sorted(found.items())                                        # by canonical edges,
    ordered.sort(key=lambda item: _invariant(links, item[0]), reverse=True)  # most-connected links first,
    ordered.sort(key=lambda item: item[1], reverse=True)                    # most binary links first
    width = len(str(len(ordered)))
    return tuple(Chain(links=links, edges=edges, name=f"{links}.{k:0{width}d}", assortment=assortment,
                       label=_label(links, assortment, edges))
                 for k, (edges, assortment) in enumerate(ordered, start=1))


#: the chains already enumerated, by number of links
_DONE: dict[int, tuple[Chain, ...]] = {}


def chains(links: int, *, progress: Callable[[int, int], None] | None = None) -> list[Chain]:
    """Every non-isomorphic planar chain of ``links`` links, revolute pairs, one degree of freedom
    and no rigid sub-chain.

    Parameters
    ----------
    links : int
        4, 6, 8, 10 or 12 (:data:`CHAIN_LINKS`); 10 links take a fraction of a second, 12
        links some seconds.
    progress : callable, optional
        Called as ``progress(done, total)`` after each link assortment (``total`` of them). The
        result is kept per number of links, so a second call is immediate (and calls nothing).

    Returns
    -------
    list of Chain
        Ordered by assortment (most binary links first), then by the degrees of the links and
        of their neighbours (highest first), then by the canonical edges; named ``"<links>.<place>"``.

    Raises
    ------
    InputError
        ``links`` is not one of :data:`CHAIN_LINKS`.
    SynthesisExtraMissing
        igraph is not installed.
    """
    if isinstance(links, bool) or not isinstance(links, (int, np.integer)) or int(links) not in CHAIN_LINKS:
        raise InputError(f"links = {links!r}: a 1-DOF planar chain with revolute pairs has 4, 6, 8, 10 or 12 links "
                         "here (3(n - 1) - 2p = 1 needs n even and n >= 4; 14 and more are not enumerated)")
    links = int(links)
    _igraph()
    if links not in _DONE:
        _DONE[links] = _enumerate(links, progress)
    return list(_DONE[links])
