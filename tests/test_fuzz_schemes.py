"""Mutation fuzzer over the shipped schemes (issue 7, build 6, second half).

What is generated
-----------------
Each shipped scheme file (``linkage.shipped_schemes()``) is mutated one edit at a time, seeded
(``SEED`` and the scheme's name), ``MUTANTS`` mutants per scheme (x ``LINKAGE_FUZZ`` when that
environment variable is set, e.g. ``LINKAGE_FUZZ=10``). An edit is one of:

- ``delete``: delete a line (not a comment or a blank line);
- ``string``: a number of a value becomes a string (``0.1`` -> ``"0.1"``);
- ``nan``: a number becomes ``nan``;
- ``negative``: a number x becomes ``-x`` (``-1`` for zero);
- ``huge``: a number becomes ``1e300``;
- ``rename``: a key loses or gains a letter (``length`` -> ``lngth``, ``links`` -> ``link``);
- ``swap``: two names (quoted strings) exchange places, in one line or between two lines.

What is checked
---------------
Each mutant, written to a file of its own name, either

1. is refused by :func:`linkage.load` with a :class:`linkage.SchemeError` whose every problem
   starts with the file's path and which names the entry: the mutated line's key or table
   (``length``, ``links.2``, ``pairs.A``, ``forces[0]`` ...), or, for a declaration that is
   well formed but cannot work, the group, the mobility or the value that does not; or
2. loads, and then analyses correctly: ``linkage.analyze`` over a turn of input angles (over
   its declared stroke for a slide input) with
   ``on_failure="mask"``, the kinetostatics of its loads (``solve_reactions``) and, when it
   declares a ``delta``, Mertsalov's course method raise nothing but
   :class:`linkage.LinkageError` subclasses, and no numpy warning (every warning is an error
   here, except the library's own ``BranchWarning`` and ``PlausibilityWarning``); statuses are 0, -1 or -2; at status-0
   positions the analogs and the balancing moment are finite and every pair closes: a revolute
   pair's two copies of its point coincide, a prismatic pair's slider point lies on its guide
   and the relative angle is the declared one, to ``CLOSURE_TOL`` x the size of the positions.

A failure lists every bad mutant with its edit, so it can be replayed from the message.
"""

from __future__ import annotations

import dataclasses
import os
import random
import re
import warnings
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import linkage
from assur.base import OK, global_point
from linkage import LinkageError, PlausibilityWarning, SchemeError
from linkage.dynamics.cycle import course_method
from linkage.kinematics.motion import BranchWarning
from linkage.kinetostatics.reactions import solve_reactions
from linkage.model.mechanism import Prismatic, Revolute

SEED = 20240607
FUZZ = max(1, int(os.environ.get("LINKAGE_FUZZ", "1") or 1))
#: mutants per shipped scheme (about 35-60 s for the nine schemes on one core)
MUTANTS = 600 * FUZZ
#: input angles of the analysis of a mutant that loads
ANGLES = np.linspace(0.0, 2 * np.pi, 25)
#: loop closure at status-0 positions, relative to the size of the positions involved
CLOSURE_TOL = 1e-9
EDITS = ("delete", "string", "nan", "negative", "huge", "rename", "swap")

SCHEMES = linkage.shipped_schemes()

# a number in a TOML value: not part of a name, a key, a string or a date
NUMBER = re.compile(r"(?<![\w.\"'-])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.\"'])")
STRING = re.compile(r'"([^"\\]*)"')
KEY = re.compile(r"^\s*([A-Za-z_][\w-]*)(?=[\s.]*[=.])")
HEADER = re.compile(r"^\s*\[\[?\s*([^\]]+?)\s*\]\]?")


# ----------------------------------------------------------------------------------------------
# mutations
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Mutant:
    """A mutated scheme: its text, the edit made and the entry edited (for the messages)."""

    text: str
    edit: str
    line: int  # 1-based number of the edited line
    before: str
    after: str
    table: str  # the TOML table of the edited line ("links.2", "loads.forces", "" at the top)
    key: str  # the key of the edited line ("length", "points" ...), "" for a table header
    other: str = ""  # the other table edited: above a deleted header (its keys now belong to
    # it), or the table of the other line of a swap between two lines
    other_key: str = ""

    def describe(self) -> str:
        return f"{self.edit} at line {self.line} [{self.table}]: {self.before.strip()!r} -> {self.after.strip()!r}"


def _code(line: str) -> tuple[str, str]:
    """The line split into its code and its comment (a ``#`` outside a string)."""
    inside = False
    for i, ch in enumerate(line):
        if ch == '"':
            inside = not inside
        elif ch == "#" and not inside:
            return line[:i], line[i:]
    return line, ""


def _tables(lines: list[str]) -> list[str]:
    """The table each line belongs to (the last header above it)."""
    current, out = "", []
    for ln in lines:
        found = HEADER.match(_code(ln)[0])
        if found:
            current = found.group(1).strip()
        out.append(current)
    return out


def _value_numbers(code: str) -> list[re.Match]:
    """Numbers in the value part of ``key = value`` (after the first '='), outside strings."""
    if "=" not in code or HEADER.match(code):
        return []
    start = code.index("=") + 1
    strings = [m.span() for m in STRING.finditer(code)]
    return [m for m in NUMBER.finditer(code, start)
            if not any(a <= m.start() < b for a, b in strings)]


def _typo(key: str, rng: random.Random) -> str:
    if len(key) > 2 and rng.random() < 0.5:
        i = rng.randrange(len(key))
        return key[:i] + key[i + 1:]
    if key.endswith("s") and rng.random() < 0.5:
        return key[:-1]
    return key + rng.choice("sx")


def mutate(text: str, rng: random.Random) -> Mutant | None:
    """One random edit of ``text``; None when the drawn edit finds nothing to edit."""
    lines = text.splitlines()
    tables = _tables(lines)
    codes = [_code(ln)[0] for ln in lines]
    edit = rng.choice(EDITS)
    candidates: list[int]
    if edit == "delete":
        candidates = [i for i, c in enumerate(codes) if c.strip()]
    elif edit in ("string", "nan", "negative", "huge"):
        candidates = [i for i, c in enumerate(codes) if _value_numbers(c)]
    elif edit == "rename":
        candidates = [i for i, c in enumerate(codes) if KEY.match(c) and not HEADER.match(c)]
    else:
        candidates = [i for i, c in enumerate(codes) if STRING.search(c)]
    if not candidates:
        return None
    i = rng.choice(candidates)
    code, comment = _code(lines[i])
    new_lines = list(lines)
    key_match = KEY.match(code)
    key = key_match.group(1) if key_match and not HEADER.match(code) else ""
    if edit == "delete":
        new_lines[i] = None
    elif edit == "rename":
        a, b = key_match.span(1)
        new_lines[i] = code[:a] + _typo(key, rng) + code[b:] + comment
    elif edit == "swap":
        here = list(STRING.finditer(code))
        if len(here) >= 2 and rng.random() < 0.5:
            m1, m2 = rng.sample(here, 2)
            if m1.start() > m2.start():
                m1, m2 = m2, m1
            new_lines[i] = (code[:m1.start()] + m2.group(0) + code[m1.end():m2.start()] + m1.group(0)
                            + code[m2.end():] + comment)
        else:
            others = [(j, m) for j, c in enumerate(codes) if j != i for m in STRING.finditer(c)
                      if m.group(1) != here[0].group(1)]
            if not others:
                return None
            m1 = rng.choice(here)
            j, m2 = rng.choice(others)
            new_lines[i] = code[:m1.start()] + m2.group(0) + code[m1.end():] + comment
            other_code, other_comment = _code(lines[j])
            new_lines[j] = other_code[:m2.start()] + m1.group(0) + other_code[m2.end():] + other_comment
            other_key = KEY.match(other_code)
            return Mutant("\n".join(new_lines) + "\n", edit, i + 1, lines[i], new_lines[i], tables[i], key,
                          tables[j], other_key.group(1) if other_key else "")
    else:
        m = rng.choice(_value_numbers(code))
        x = float(m.group(0))
        new = {"string": f'"{m.group(0)}"', "nan": "nan", "huge": "1e300",
               "negative": repr(-x) if x != 0 else "-1"}[edit]
        new_lines[i] = code[:m.start()] + new + code[m.end():] + comment
    after = "" if new_lines[i] is None else new_lines[i]
    text = "\n".join(ln for ln in new_lines if ln is not None) + "\n"
    other = tables[i - 1] if edit == "delete" and HEADER.match(code) and i > 0 else ""
    return Mutant(text, edit, i + 1, lines[i], after, tables[i], key, other)


def mutants(name: str, count: int) -> list[Mutant]:
    """``count`` seeded mutants of the shipped scheme ``name``."""
    rng = random.Random(SEED ^ zlib.crc32(name.encode()))
    text = SCHEMES[name].read_text(encoding="utf-8")
    found: list[Mutant] = []
    while len(found) < count:
        m = mutate(text, rng)
        if m is not None:
            found.append(m)
    return found


# ----------------------------------------------------------------------------------------------
# checks
# ----------------------------------------------------------------------------------------------

#: words by which a message names an entry when the declaration is well formed but cannot work
#: (a group that never assembles, a wrong mobility, an assembly condition, an output ...)
#: (a declared input range that the mutated geometry no longer assembles over is named as written:
#: ``range_deg = [a, b]`` for a crank's angles, ``range = [a, b]`` for a slide input's stroke)
CONSEQUENCE = re.compile(r"II-[A-Z]{3}\(|mobility|assembly|output|input|extreme|stroke|does not move|"
                         r"decompos|group|branch|line \d+|\brange(_deg)? = \[")


def entry_names(m: Mutant) -> list[str]:
    """Strings of which one names the mutated entry in a message."""
    names = [k for k in (m.key, m.other_key) if k]
    for table in (m.table, m.other):
        parts = [p.strip().strip('"') for p in table.split(".") if p.strip()]
        if parts:
            names += [f"'{parts[-1]}'", f".{parts[-1]}", f"{parts[-1]}[", table, parts[0]]
    # a swapped or deleted name is named where it is used
    names += [f"'{s}'" for ln in (m.before, m.after) for s in STRING.findall(_code(ln)[0])]
    return [n for n in names if n]


def check_refusal(exc: SchemeError, path: Path, m: Mutant) -> str | None:
    """None when the refusal names the file and the entry; else what is wrong."""
    problems = exc.problems
    if not problems:
        return "a SchemeError without problems"
    stray = [p for p in problems if not str(p).startswith(f"{path}: ")]
    if stray:
        return f"problems that do not start with the file's path: {stray}"
    text = "\n".join(problems)
    if any(n in text for n in entry_names(m)) or CONSEQUENCE.search(text):
        return None
    return f"no problem names the entry ({entry_names(m)}): {problems}"


def closure_errors(motion) -> list[str]:
    """Pairs that do not close at status-0 positions (relative to the positions' size)."""
    mech, ok = motion.mechanism, motion.status == OK
    if not ok.any():
        return []
    bad = []
    for name, pair in mech.pairs.items():
        a, b = pair.links
        pa, pb = motion.poses[a][ok], motion.poses[b][ok]
        la, lb = mech.links[a], mech.links[b]
        if isinstance(pair, Revolute):
            ra, rb = global_point(pa, la.points[pair.point]), global_point(pb, lb.points[pair.point])
            gap = np.hypot(*(ra - rb).T)
            scale = mech.size + np.maximum(np.hypot(*ra.T), np.hypot(*rb.T))
        else:
            assert isinstance(pair, Prismatic)
            guide = la.guides[pair.guide]
            g = global_point(pa, guide.point)
            u = np.column_stack([np.cos(pa[:, 2] + guide.angle), np.sin(pa[:, 2] + guide.angle)])
            p = global_point(pb, lb.points[pair.point])
            d = p - g
            gap = np.abs(u[:, 0] * d[:, 1] - u[:, 1] * d[:, 0])
            turn = np.angle(np.exp(1j * (pb[:, 2] - pa[:, 2] - guide.angle - pair.angle)))
            gap = np.maximum(gap, np.abs(turn) * mech.size)
            scale = mech.size + np.maximum(np.hypot(*g.T), np.hypot(*p.T))
        worst = np.max(gap / scale)
        if not worst <= CLOSURE_TOL:
            bad.append(f"pair '{name}' does not close: relative gap {worst:.3g}")
    return bad


def positions(mech) -> np.ndarray:
    """Where a loaded mutant is analysed: a turn of input angles (rad) for a crank, its declared
    stroke (m, 25 slides) for a slide input."""
    if mech.inputs and not mech.coordinate.is_angle and mech.input_range is not None:
        return np.linspace(*mech.input_range, len(ANGLES))
    return ANGLES


def check_analysis(mech) -> str | None:
    """None when the loaded mutant analyses correctly; else what is wrong."""
    try:
        motion = linkage.analyze(mech, positions(mech), order=2, omega=1.0, eps=0.0, on_failure="mask")
    except LinkageError:
        return None
    if not np.isin(motion.status, (0, -1, -2)).all():
        return f"statuses other than 0, -1, -2: {np.unique(motion.status)}"
    ok = motion.status == OK
    for k, d in list(motion.first.items()) + list(motion.second.items()):
        if not np.isfinite(d[ok]).all():
            return f"non-finite analogs of link '{k}' at status-0 positions"
    problems = closure_errors(motion)
    if problems:
        return "; ".join(problems)
    try:
        reactions = solve_reactions(motion)
    except LinkageError:
        return None
    if not np.isfinite(reactions.balancing_moment[ok]).all():
        return "non-finite balancing moment at status-0 positions"
    spec = mech.parts.get("dynamics")
    if spec is not None and spec.delta is not None:
        try:
            law = course_method(mech)
        except LinkageError:
            return None
        if not (np.isfinite(law.omega).all() and np.isfinite(law.eps).all()):
            return "non-finite omega or eps of the course method"
    return None


def run_mutant(m: Mutant, path: Path) -> tuple[str, str | None]:
    """``("refused" or "loaded", None)`` when the mutant behaves (refused by name, or analyses
    correctly); else the outcome and what is wrong."""
    path.write_text(m.text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", BranchWarning)
        warnings.simplefilter("ignore", PlausibilityWarning)  # a valid value seldom meant (gravity up): a note
        try:
            mech = linkage.load(path)
        except SchemeError as exc:
            return "refused", check_refusal(exc, path, m)
        except Exception as exc:  # noqa: BLE001 -- what the fuzzer is looking for
            return "refused", f"load raised {type(exc).__name__} instead of a SchemeError: {exc}"
        try:
            return "loaded", check_analysis(mech)
        except Exception as exc:  # noqa: BLE001
            return "loaded", f"{type(exc).__name__}: {exc}"


# ----------------------------------------------------------------------------------------------
# the tests
# ----------------------------------------------------------------------------------------------


def test_mutations_edit_what_they_say():
    """The mutator itself: each edit changes exactly the described line the described way."""
    text = SCHEMES["slider_crank"].read_text(encoding="utf-8")
    rng = random.Random(1)
    seen = set()
    for _ in range(300):
        m = mutate(text, rng)
        if m is None:
            continue
        seen.add(m.edit)
        assert m.text != text, m.describe()
        old_lines, new_lines = text.splitlines(), m.text.splitlines()
        if m.edit == "delete":
            assert len(new_lines) == len(old_lines) - 1
            continue
        assert len(new_lines) == len(old_lines)
        changed = [k for k, (a, b) in enumerate(zip(old_lines, new_lines)) if a != b]
        assert m.line - 1 in changed and len(changed) <= 2, m.describe()
        after = new_lines[m.line - 1]
        if m.edit == "nan":
            assert "nan" in after
        elif m.edit == "huge":
            assert "1e300" in after
        elif m.edit == "string":
            assert after.count('"') == old_lines[m.line - 1].count('"') + 2
        elif m.edit == "rename":
            assert m.key and m.key not in _code(after)[0].split("=")[0].split()
    assert seen == set(EDITS)


def test_the_checks_can_fail():
    """The checks can fail: a refusal that does not name the entry, and a pair that does not
    close, are caught."""
    m = Mutant("", "rename", 1, "length = 0.1", "lenth = 0.1", "links.1", "length")
    exc = SchemeError(["/x/y.toml: something is wrong"])
    assert check_refusal(exc, Path("/x/y.toml"), m) is not None
    assert check_refusal(SchemeError(["elsewhere: links.1: bad"]), Path("/x/y.toml"), m) is not None
    assert check_refusal(SchemeError(["/x/y.toml: links.1: unknown keys ['lenth']"]), Path("/x/y.toml"), m) is None
    motion = linkage.analyze(linkage.load("four_bar"), ANGLES)
    assert closure_errors(motion) == []
    broken = motion.poses["2"].copy()
    broken[:, 0] += 1e-3
    shifted = dataclasses.replace(motion, poses={**motion.poses, "2": broken})
    assert closure_errors(shifted)


def mutant_count(name: str) -> int:
    """:data:`MUTANTS`, a tenth of it for a scheme with a group whose modes are found by Newton's
    method from random starts and traced (each mutant that loads costs a trace, ~0.25 s; the
    full count runs with LINKAGE_FUZZ=10)."""
    from assur.generic import NewtonGroup

    groups = linkage.structure_of(linkage.load(name)).groups
    traced = any(isinstance(g, NewtonGroup) and type(g).modes is NewtonGroup.modes for g in groups)
    return MUTANTS // 10 if traced else MUTANTS


@pytest.mark.parametrize("name", list(SCHEMES))
def test_every_mutant_is_refused_by_name_or_analyses_correctly(tmp_path, name):
    bad = []
    outcomes = {"refused": 0, "loaded": 0}
    count = mutant_count(name)
    for k, m in enumerate(mutants(name, count)):
        path = tmp_path / f"{name}_mutant_{k}.toml"
        outcome, problem = run_mutant(m, path)
        outcomes[outcome] += 1
        if problem is not None:
            bad.append(f"mutant {k} ({m.describe()}): {problem}")
    assert not bad, f"{len(bad)} of {count} mutants of {name} misbehave:\n" + "\n".join(bad[:20])
    # the fuzzer tests both outcomes, not only the loader's refusals
    assert outcomes["refused"] > 0 and outcomes["loaded"] > 0, outcomes
