"""Structural synthesis: the mechanisms of every 1-DOF chain of N links, their Assur groups and formulas.

A mechanism of the synthesis (:class:`Topology`) is a chain (:class:`~.chains.Chain`: links joined
by revolute pairs), one of its links as the frame (an inversion, :func:`~.chains.inversions`) and
one link pinned to the frame as the crank (:func:`~.chains.input_choices`). :func:`topology`
names its links and pairs -- the frame ``0``, the crank ``1``, the others ``2 ... N-1`` in the
order the groups place them; the crank bearing ``O``, the other pairs ``A, B, ...`` -- and
decomposes it into Assur groups by the rule of :func:`linkage.structure.decompose`
(:func:`linkage.structure.group_links`: at each step the smallest set of unknown links that forms
a group, ties broken by the sorted link names), on the graph alone. Each group is named by
the solver that binds it (:func:`assur.registry.solver_for`: ``II-RRR(2,3)`` for a dyad,
``III-RRR-RRR(...)`` for the triad, ``IV(...)`` and up for the groups solved by Newton's method),
so that the formula is the one ``linkage analyze`` prints for the scheme. :func:`mechanisms`
lists every mechanism of N links, :func:`catalogue` counts the mechanisms that use each kind of
group (:class:`GroupCount`). The geometry search is :mod:`~.synthesis_geometry`.

>>> found = mechanisms(6)
>>> len({(t.chain, t.frame) for t in found}), len(found), found[0].formula
(5, 9, 'I(0,1) → II-RRR(2,3) → II-RRR(4,5)')
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass


from assur import RevoluteJoint, solver_for
from assur.generic import group_class_of

from ..errors import LinkageError
from ..structure import group_links
from .chains import Chain, chains, input_choices, inversions

__all__ = [
    "GroupCount",
    "GroupUse",
    "Topology",
    "catalogue",
    "class_rank",
    "mechanisms",
    "topology",
]

#: names of the pairs other than the crank bearing ``O``, in order (no I or O: they read as digits)
PAIR_LETTERS = "ABCDEFGHJKLMNPQRSTUVWXYZ"
ROMAN = ("I", "II", "III", "IV", "V", "VI", "VII", "VIII", "IX", "X")


@dataclass(frozen=True)
class GroupUse:
    """One Assur group of a mechanism.

    Attributes
    ----------
    label : str
        As the structural formula writes it (``"II-RRR(2,3)"``, ``"IV(2,3,4,5)"``).
    links : tuple of str
        Its links (mechanism names).
    pairs : int
        Its pairs, inner and outer.
    group_class : str
        Assur's class, a Roman numeral (``"II"`` ...).
    """

    label: str
    links: tuple[str, ...]
    pairs: int
    group_class: str

    @property
    def kind(self) -> str:
        """The kind of group in words: ``"dyad"``, ``"triad"``, ``"tetrad"`` (4 links, class IV), or
        ``"6-link group"`` ..."""
        return kind_words(len(self.links), self.group_class)


def kind_words(links: int, group_class: str) -> str:
    """``"dyad"`` (2 links), ``"triad"`` (4 links, class III), ``"tetrad"`` (4 links, class IV), else
    ``"<n>-link group"``."""
    if links == 2:
        return "dyad"
    if links == 4:
        return "triad" if group_class == "III" else "tetrad" if group_class == "IV" else "4-link group"
    return f"{links}-link group"


def class_rank(group_class: str) -> int:
    """The number of a Roman class numeral (``"IV"`` -> 4)."""
    return ROMAN.index(group_class) + 1 if group_class in ROMAN else int(group_class)


@dataclass(frozen=True)
class Topology:
    """One mechanism of the synthesis: a chain with a frame and a crank, decomposed.

    Attributes
    ----------
    chain : str
        The chain's name (``"8.07"``).
    chain_label : str or None
        ``"Watt"``, ``"Stephenson"`` ... where known.
    links : int
        Number of links N.
    frame, crank : int
        The chain's links (0 .. N-1 in its labelling) that are the frame and the crank.
    names : tuple of str
        The mechanism's name of each link of the chain (index: the chain's link).
    pairs : tuple of (str, str, str)
        Every pair: its name and the two links it joins (mechanism names), sorted by name.
    groups : tuple of GroupUse
        The Assur groups in the order of kinematic analysis.
    inversion : int
        1-based number of the frame among the chain's inversions.
    """

    chain: str
    chain_label: str | None
    links: int
    frame: int
    crank: int
    names: tuple[str, ...]
    pairs: tuple[tuple[str, str, str], ...]
    groups: tuple[GroupUse, ...]
    inversion: int = 1

    @property
    def id(self) -> str:
        """``"8.07-f3-c5"``: the chain, the frame and the crank (the chain's link numbers)."""
        return f"{self.chain}-f{self.frame}-c{self.crank}"

    @property
    def formula(self) -> str:
        """The structural formula, ``I(0,1) → II-RRR(2,3) → ...`` (as ``Structure.formula``)."""
        return " → ".join(["I(0,1)", *(g.label for g in self.groups)])

    @property
    def mechanism_class(self) -> str:
        """The mechanism's class: the highest class of its groups (Roman)."""
        return max((g.group_class for g in self.groups), key=class_rank)


# ----------------------------------------------------------------------------------------------
# decomposition on the graph
# ----------------------------------------------------------------------------------------------


def _decomposed(names: Sequence[str], frame: str, crank: str,
                pairs: list[tuple[str, str, str]]) -> list[tuple[str, ...]]:
    """The groups (link sets, in order) of the mechanism with these link names and pairs."""
    known = {frame, crank}
    joints = {p: RevoluteJoint(p, a, b, (0.0, 0.0), (0.0, 0.0)) for p, a, b in pairs}
    used = {p for p, a, b in pairs if {a, b} == {frame, crank}}
    unknown = sorted(set(names) - known)
    groups = []
    while unknown:
        group = group_links(unknown, known, joints, used)     # the rule of linkage.structure.decompose
        if group is None:
            raise LinkageError(f"links {unknown} cannot be decomposed into Assur groups on {sorted(known)}")
        groups.append(tuple(group))
        known |= set(group)
        used |= {p for p, a, b in pairs if a in known and b in known}
        unknown = [k for k in unknown if k not in known]
    return groups


def _group_use(links: tuple[str, ...], known: set[str], pairs: list[tuple[str, str, str]]) -> GroupUse:
    """The group's label as its solver writes it, its pairs and its class."""
    inside = set(links) | known
    joints = [RevoluteJoint(p, a, b, (0.0, 0.0), (0.0, 0.0)) for p, a, b in sorted(pairs)
              if (a in links or b in links) and a in inside and b in inside]
    solver = solver_for(links, joints, known, 1.0)
    group_class = group_class_of(links, joints)
    label = repr(solver) if solver is not None else f"{group_class}({','.join(links)})"
    return GroupUse(label, tuple(links), len(joints), getattr(solver, "group_class", group_class))


def topology(chain: Chain, frame: int, crank: int, inversion: int = 1) -> Topology:
    """The mechanism of ``chain`` with link ``frame`` as the frame and ``crank`` as the input.

    The links are named ``0`` (frame), ``1`` (crank), then ``2 ... N-1`` in the order their groups
    place them (within a group, by their distance from the frame in the chain, then their number);
    the crank bearing is ``O``, the other pairs ``A, B, ...`` in the order of their links' names.

    Raises
    ------
    LinkageError
        When ``crank`` is not adjacent to ``frame``.
    """
    edges = [tuple(e) for e in chain.edges]
    if (min(frame, crank), max(frame, crank)) not in {(min(e), max(e)) for e in edges}:
        raise LinkageError(f"chain {chain.name}: link {crank} is not pinned to link {frame}, it cannot be the crank")
    order = _bfs_order(chain.links, edges, frame, crank)
    provisional = {link: str(i) for i, link in enumerate(order)}
    pairs = [(f"p{i}", provisional[a], provisional[b]) for i, (a, b) in enumerate(edges)]
    groups = _decomposed(list(provisional.values()), "0", "1", pairs)
    rank = {name: i for i, name in enumerate(provisional.values())}
    final_order = ["0", "1"] + [k for g in groups for k in sorted(g, key=rank.get)]
    rename = {old: str(i) for i, old in enumerate(final_order)}
    names = tuple(rename[provisional[link]] for link in range(chain.links))
    ends = sorted((sorted((names[a], names[b]), key=int) for a, b in edges), key=lambda e: (int(e[1]), int(e[0])))
    letters = iter(PAIR_LETTERS)
    pairs = [("O" if set(e) == {"0", "1"} else next(letters), e[0], e[1]) for e in ends]
    pairs.sort()
    known = {"0", "1"}
    uses = []
    for group in _decomposed(list(names), "0", "1", pairs):
        uses.append(_group_use(group, known, [p for p in pairs if p[0] != "O"]))
        known |= set(group)
    return Topology(chain.name, chain.label, chain.links, frame, crank, names, tuple(pairs), tuple(uses), inversion)


def _bfs_order(links: int, edges: list[tuple[int, int]], frame: int, crank: int) -> list[int]:
    """The chain's links by distance from the frame (the crank second), then by number."""
    near = {k: sorted({b for a, b in edges if a == k} | {a for a, b in edges if b == k}) for k in range(links)}
    order, seen = [frame, crank], {frame, crank}
    queue = [frame, crank]
    while queue:
        here = queue.pop(0)
        for there in near[here]:
            if there not in seen:
                seen.add(there)
                order.append(there)
                queue.append(there)
    return order + [k for k in range(links) if k not in seen]


def mechanisms(links: int, *, chain_list: Iterable[Chain] | None = None,
               progress: Callable | None = None) -> list[Topology]:
    """Every mechanism of the 1-DOF chains of ``links`` links: each inversion with each input.

    Parameters
    ----------
    links : int
        N: 4, 6, 8, 10 or 12 (:func:`~.chains.chains`).
    chain_list : iterable of Chain, optional
        The chains (default: :func:`~.chains.chains` of ``links``).
    progress : callable, optional
        ``progress(iterable, total)`` wrapping the loop over the chains (a tqdm bar).

    Returns
    -------
    list of Topology
        In the order of the chains, their inversions and their input choices.
    """
    found = list(chains(links) if chain_list is None else chain_list)
    loop = found if progress is None else progress(found, len(found))
    result = []
    for chain in loop:
        for number, frame in enumerate(inversions(chain), start=1):
            result.extend(topology(chain, frame, crank, number) for crank in input_choices(chain, frame))
    return result


@dataclass(frozen=True)
class GroupCount:
    """A kind of Assur group that occurs, and how many mechanisms use it.

    Attributes
    ----------
    kind : str
        ``"dyad"``, ``"triad"``, ``"tetrad"``, ``"6-link group"`` ...
    group_class : str
        Assur's class (Roman).
    links, pairs : int
        Its links and pairs (inner and outer).
    mechanisms : int
        The mechanisms with at least one such group.
    occurrences : int
        How many such groups there are over all mechanisms.
    """

    kind: str
    group_class: str
    links: int
    pairs: int
    mechanisms: int
    occurrences: int


def catalogue(found: Iterable[Topology]) -> list[GroupCount]:
    """The kinds of Assur group that occur in ``found``, by links, pairs and class (smallest first)."""
    using, total = Counter(), Counter()
    for t in found:
        keys = [(len(g.links), g.pairs, class_rank(g.group_class)) for g in t.groups]
        total.update(keys)
        using.update(set(keys))
    return [GroupCount(kind_words(n, ROMAN[c - 1] if c <= len(ROMAN) else str(c)),
                       ROMAN[c - 1] if c <= len(ROMAN) else str(c), n, p, using[(n, p, c)], total[(n, p, c)])
            for n, p, c in sorted(total)]
