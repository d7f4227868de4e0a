"""The model's Mechanism is immutable for real (linkage/model/mechanism.py).

- its mappings (links, pairs, extra, input_laws; a link's points and guides) refuse assignment and
  deletion, and are copies: changing what the builder was given changes no mechanism;
- equal mechanisms are equal after a round trip through TOML and through pickle (worker
  processes), and hash equal;
- new mechanisms come from ``dataclasses.replace``, ``with_extra`` and ``with_input_laws``; only
  the ``cache`` of derived results changes (``mech.parts`` is ``cache["parts"]``).
"""

from __future__ import annotations

import copy
import dataclasses
import pickle

import pytest

import linkage
from linkage import MechanismBuilder, SchemeError
from linkage.model.input_laws import InputLaw
from linkage.model.mechanism import Link, ReadOnlyMapping
from linkage.structure import structure_of


@pytest.fixture(scope="module")
def five_bar():
    """A shipped scheme with further sections (loads) and a further input's law."""
    return linkage.load("five_bar_two_input")


def _four_bar(points: dict | None = None, extra: dict | None = None):
    b = MechanismBuilder("four_bar")
    b.link("0", points=points if points is not None else {"O": (0.0, 0.0), "C": (0.3, 0.0)})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "B"), length=0.3)
    b.link("3", line=("C", "B"), length=0.25)
    for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, a, c)
    b.inputs("1").assembly("B", left_of=("A", "C"))
    return b.build(**(extra or {}))


@pytest.mark.parametrize("attribute", ["links", "pairs", "extra", "input_laws"])
def test_the_mechanisms_mappings_refuse_assignment(five_bar, attribute):
    mapping = getattr(five_bar, attribute)
    assert isinstance(mapping, ReadOnlyMapping)
    key = next(iter(mapping))
    with pytest.raises(TypeError, match="does not support item assignment"):
        mapping[key] = None
    with pytest.raises(TypeError, match="does not support item assignment"):
        mapping["new"] = None
    with pytest.raises(TypeError, match="does not support item deletion"):
        del mapping[key]
    for method in ("update", "pop", "setdefault", "clear", "popitem"):
        assert not hasattr(mapping, method)
    with pytest.raises(AttributeError):
        mapping._items = {}
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(five_bar, attribute, {})


@pytest.mark.parametrize("attribute", ["points", "guides"])
def test_a_links_points_and_guides_refuse_assignment(attribute):
    mech = linkage.load("slider_crank")
    link = next(lk for lk in mech.links.values() if getattr(lk, attribute))
    mapping = getattr(link, attribute)
    assert isinstance(mapping, ReadOnlyMapping)
    name = next(iter(mapping))
    with pytest.raises(TypeError, match="does not support item assignment"):
        mapping[name] = mapping[name]
    with pytest.raises(TypeError, match="does not support item deletion"):
        del mapping[name]


def test_the_mechanism_keeps_copies_of_what_it_was_given():
    points = {"O": (0.0, 0.0), "C": (0.3, 0.0)}
    extra = {"note": {"text": "as declared"}}
    mech = _four_bar(points, extra)
    points["D"] = (1.0, 1.0)
    extra["more"] = 1
    assert "D" not in mech.links["0"].points and "more" not in mech.extra
    given = {"O": (0.0, 0.0)}
    link = Link("0", points=given)
    given["P"] = (1.0, 0.0)
    assert dict(link.points) == {"O": (0.0, 0.0)}


def test_read_only_mappings_compare_like_dicts():
    mapping = ReadOnlyMapping({"a": 1, "b": (2.0, 3.0)})
    assert mapping == {"a": 1, "b": (2.0, 3.0)} and {"b": (2.0, 3.0), "a": 1} == mapping
    assert mapping == ReadOnlyMapping({"b": (2.0, 3.0), "a": 1}) and mapping != {"a": 1}
    assert hash(mapping) == hash(ReadOnlyMapping({"b": (2.0, 3.0), "a": 1}))
    assert ReadOnlyMapping.of(mapping) is mapping
    assert dict(mapping.items()) == {"a": 1, "b": (2.0, 3.0)} and mapping.get("c", 4) == 4


@pytest.mark.parametrize("name", ["four_bar", "five_bar_two_input", "cylinder_boom", "slotted_link"])
def test_equal_mechanisms_hash_equal(name):
    mech = linkage.load(name)
    again = linkage.loads(linkage.dumps(mech))
    assert again == mech and again is not mech
    assert hash(again) == hash(mech)
    assert len({mech, again, linkage.load(name)}) == 1
    assert hash(mech.links[mech.frame]) == hash(again.links[mech.frame])


@pytest.mark.parametrize("name", ["four_bar", "five_bar_two_input", "cylinder_boom"])
def test_a_mechanism_pickles_and_unpickles_equal(name):
    mech = linkage.load(name)
    structure_of(mech)                  # a filled cache travels too
    back = pickle.loads(pickle.dumps(mech))
    assert back == mech and hash(back) == hash(mech)
    assert back.input_laws == mech.input_laws and back.extra == mech.extra
    assert isinstance(back.links, ReadOnlyMapping) and isinstance(back.links[mech.frame].points, ReadOnlyMapping)
    with pytest.raises(TypeError):
        back.links["new"] = None
    assert copy.deepcopy(mech) == mech


def test_replace_and_with_extra_make_new_mechanisms(five_bar):
    structure_of(five_bar)
    assert "structure" in five_bar.cache
    renamed = dataclasses.replace(five_bar, description="another")
    assert renamed.description == "another" and renamed.links == five_bar.links
    assert isinstance(renamed.links, ReadOnlyMapping) and renamed.cache == {}
    assert renamed == dataclasses.replace(five_bar, description="another")

    more = five_bar.with_extra(note={"text": "added"})
    assert dict(more.extra) == {**five_bar.extra, "note": {"text": "added"}}
    assert "note" not in five_bar.extra and isinstance(more.extra, ReadOnlyMapping)
    assert more != five_bar


def test_with_input_laws_validates_and_copies(five_bar):
    (further,) = five_bar.inputs[1:]
    turned = five_bar.with_input_laws(**{further: InputLaw(ratio=-1.0, phase=0.5)})
    assert turned.input_laws[further] == InputLaw(ratio=-1.0, phase=0.5)
    assert five_bar.input_laws[further] != turned.input_laws[further]
    assert isinstance(turned.input_laws, ReadOnlyMapping)
    with pytest.raises(SchemeError, match="is not an input link"):
        five_bar.with_input_laws(**{five_bar.frame: InputLaw()})


def test_the_cache_stays_writable(five_bar):
    mech = linkage.loads(linkage.dumps(five_bar))
    mech.cache["mine"] = 1
    assert mech.parts is mech.cache["parts"]
    assert mech == five_bar and hash(mech) == hash(five_bar)
