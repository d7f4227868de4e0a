"""Scheme files: read, validate and write declarative mechanisms (TOML).

The format is documented with a complete annotated example in ``schemes/README.md``.

>>> import linkage
>>> mech = linkage.load("four_bar")
>>> linkage.loads(linkage.dumps(mech)) == mech
True
"""

from __future__ import annotations

import copy
import difflib
import importlib.resources
import math
import re
import tomllib
from pathlib import Path
from typing import Any, Callable, Mapping

from ..errors import SchemeError
from .builder import MechanismBuilder
from .mechanism import Mechanism, Prismatic, Revolute
from .numbers import MAX_ANGLE_DEG, MAX_MAGNITUDE, angle_from, is_number, unknown_keys
from .plausibility import parse_checks, warn_implausible

__all__ = ["load", "loads", "dumps", "save", "shipped_schemes", "scheme_path", "section_of",
           "register_section", "register_check", "SECTION_PARSERS", "LOAD_CHECKS"]

TOP_KEYS = {"name", "description", "frame", "input", "inputs", "input_laws", "output", "links", "pairs",
            "assembly", "range", "range_deg"}
LINK_KEYS = {"line", "length", "points", "guides", "mass", "com", "inertia"}
PAIR_KEYS = {"kind", "links", "at", "guide", "angle", "angle_deg"}
#: keys of a link that place its points or guides (or its centre of mass, which its mass needs):
#: a link that misspells one of them is incomplete
LINK_GEOMETRY = {"line", "length", "points", "guides", "com"}
PAIR_KINDS = {"R": "R", "revolute": "R", "P": "P", "prismatic": "P"}

#: Further top-level sections (``loads``, ``dynamics`` ...): name -> parser
#: ``(mechanism, raw section or None) -> (typed part, problems)``. Registered by the modules that
#: own them; a scheme's sections are parsed once, when it is loaded (see :func:`section_of`).
SECTION_PARSERS: dict[str, Callable[[Mechanism, Any], tuple[Any, list[str]]]] = {}
#: section -> the sections its parser reads (``loads`` reads the cycle of ``dynamics``)
_REQUIRES: dict[str, tuple[str, ...]] = {}


#: What a later stage checks of every mechanism loaded from a scheme, in order, before its further
#: sections are parsed: ``check(mech, data)`` raises :class:`SchemeError` (its structure, that its
#: groups assemble: registered by :mod:`linkage.kinematics.checks`).
LOAD_CHECKS: list[Callable[[Mechanism, Mapping[str, Any]], None]] = []


def register_check(check: Callable[[Mechanism, Mapping[str, Any]], None]) -> None:
    """Run ``check(mech, data)`` on every mechanism loaded from a scheme (``data``: the parsed
    file), after it is built and before its further sections are parsed; it raises
    :class:`SchemeError` naming the problem."""
    if check not in LOAD_CHECKS:
        LOAD_CHECKS.append(check)


def register_section(name: str, parser: Callable[[Mechanism, Any], tuple[Any, list[str]]],
                     requires: tuple[str, ...] = ()) -> None:
    """Register the parser of a further top-level section ``name``.

    Parameters
    ----------
    name : str
        The section (``"loads"``).
    parser : callable
        ``parser(mech, raw) -> (typed part, problems)``; ``raw`` is None when the scheme has no
        such section. It may read the typed parts it ``requires`` with :func:`section_of`.
    requires : tuple of str
        Sections parsed before this one.
    """
    SECTION_PARSERS[name] = parser
    _REQUIRES[name] = tuple(requires)


#: ``[checks] silence = [...]``: the plausibility notes a scheme silences (:mod:`.plausibility`)
register_section("checks", parse_checks)


def _section_order() -> list[str]:
    """Registered sections, each after the sections it requires."""
    order: list[str] = []

    def visit(name: str) -> None:
        for dep in _REQUIRES.get(name, ()):
            visit(dep)
        if name in SECTION_PARSERS and name not in order:
            order.append(name)

    for name in SECTION_PARSERS:
        visit(name)
    return order


def section_of(mech: Mechanism, name: str) -> Any:
    """The typed part ``name`` of a mechanism (its ``Loads``, its ``DynamicsSpec`` or None).

    Parsed once from ``mech.extra[name]`` and kept in ``mech.parts``: a loaded scheme has every
    part already; a mechanism built in Python (or by :meth:`Mechanism.with_extra`) has it parsed
    on first use.

    Raises
    ------
    SchemeError
        When the section is declared wrongly (every problem, naming the mechanism).
    """
    parts = mech.parts
    if name not in parts:
        for dep in _REQUIRES.get(name, ()):
            if dep in SECTION_PARSERS:
                section_of(mech, dep)
        value, problems = SECTION_PARSERS[name](mech, mech.extra.get(name))
        if problems:
            raise SchemeError([f"mechanism '{mech.name}' {name}: {p}" for p in problems])
        parts[name] = value
    return parts[name]


def schemes_dirs() -> list[Path]:
    """The folders that hold the shipped schemes (the installed package's, the source tree's)."""
    dirs = []
    try:
        dirs.append(Path(str(importlib.resources.files("linkage.schemes"))))
    except (ModuleNotFoundError, TypeError):
        pass
    dirs.append(Path(__file__).resolve().parents[2] / "schemes")
    return [d for d in dirs if d.is_dir()]


def shipped_schemes() -> dict[str, Path]:
    """Shipped scheme names -> files, sorted by name."""
    found: dict[str, Path] = {}
    for d in schemes_dirs():
        for f in sorted(d.glob("*.toml")):
            found.setdefault(f.stem, f)
    return dict(sorted(found.items()))


def scheme_path(name_or_path: str | Path) -> Path:
    """The file of a shipped scheme name, or the given path."""
    return shipped_or_path(name_or_path, shipped_schemes(), "scheme")


def shipped_or_path(name_or_path: str | Path, shipped: Mapping[str, Path], what: str) -> Path:
    """The file of a shipped ``what`` ("scheme", "template") by name, or the given path; a folder,
    a missing file or an unknown name is refused naming it (and the shipped names)."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        if path.is_dir():
            raise SchemeError(f"{path}: is a folder, not a {what} file (give the path of a .toml file)")
        if not path.is_file():
            raise SchemeError(f"{path}: no such {what} file")
        return path
    if str(name_or_path) not in shipped:
        meant = difflib.get_close_matches(str(name_or_path), list(shipped), n=1)
        raise SchemeError(f"unknown {what} {str(name_or_path)!r}: not a file, and not a shipped "
                          f"{what} ({', '.join(shipped)})" + (f"; did you mean {meant[0]!r}?" if meant else ""))
    return shipped[str(name_or_path)]


def read_text(path: Path, what: str = "scheme") -> str:
    """The UTF-8 text of a scheme or template file; an unreadable file is refused naming it."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise SchemeError(f"{path}: not a text file in UTF-8 (byte {exc.start} cannot be read); a "
                          f"{what} file is TOML text") from None
    except OSError as exc:
        raise SchemeError(f"{path}: cannot be read ({exc.strerror})") from None


def load(name_or_path: str | Path) -> Mechanism:
    """Load a shipped scheme by name (``"slider_crank"``) or any scheme file by path.

    Raises
    ------
    SchemeError
        Listing every problem, each prefixed with the file name.
    """
    path = scheme_path(name_or_path)
    return loads(read_text(path), source=str(path), default_name=path.stem)


def loads(text: str, source: str = "<string>", default_name: str = "mechanism") -> Mechanism:
    """Parse and validate a scheme given as TOML text (``source`` names it in errors)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SchemeError(f"{source}: malformed TOML: {exc}{_context(text, str(exc))}") from None
    try:
        mech = from_dict(data, default_name)
    except SchemeError as exc:
        raise SchemeError([f"{source}: {p}" for p in exc.problems]) from None
    warn_implausible(data, mech, source)  # valid, but almost never meant: a note naming the key
    return mech


def _context(text: str, message: str) -> str:
    """The offending line (and the table it is in) of a TOML error message ``(at line N, ...)``."""
    found = re.search(r"at line (\d+)", message)
    if not found:
        return ""
    lines = text.splitlines()
    number = int(found.group(1))
    if not 1 <= number <= len(lines):
        return ""
    tables = [ln.strip() for ln in lines[:number] if re.match(r"\s*\[", ln)]
    where = f" in {tables[-1].split('#')[0].strip()}" if tables else ""
    return f"; line {number}{where}: {lines[number - 1].strip()!r}"


def from_dict(data: Mapping[str, Any], default_name: str = "mechanism") -> Mechanism:
    """Build and validate a mechanism from a parsed scheme, and parse its further sections once.

    Structure first: the declaration of links, pairs, inputs, assembly and output; then the
    mobility and the decomposition into groups; then the further sections (``dynamics``,
    ``loads``), parsed into the mechanism's typed parts (``mech.parts``). Each stage runs only
    when the one before found no problem, so a problem is reported once, as its root cause, and
    not through what follows from it.

    Raises
    ------
    SchemeError
        Every problem of the first stage that has any.
    """
    if "template" in data:
        raise SchemeError("this is an assignment template (it has a [template] table, and its values are "
                          "expressions of parameters), not a scheme: make variants of it with `linkage variants` "
                          "or linkage.course.template.load_template (docs/templates.md)")
    problems: list[str] = []
    extra_sections = {k: v for k, v in data.items() if k in SECTION_PARSERS}
    name = data.get("name", default_name)
    builder = MechanismBuilder(str(name), str(data.get("description", "")), str(data.get("frame", "0")))
    if unknown_keys(data, TOP_KEYS | set(SECTION_PARSERS), "top-level", problems) & {"input", "inputs"}:
        builder.reject(inputs=True)
    links = _table(data, "links", problems)
    for lname, spec in links.items():
        if not isinstance(spec, Mapping):
            problems.append(f"links.{lname}: expected a table, got {spec!r}")
            builder.reject(lname)
            continue
        if unknown_keys(spec, LINK_KEYS, f"links.{lname}", problems) & LINK_GEOMETRY:
            builder.reject(lname, _declared_names(spec))  # incomplete: say so once, not its follow-ons
            continue
        line = spec.get("line")
        builder.link(lname, line=tuple(line) if isinstance(line, list) else line, length=spec.get("length"),
                     points=_table(spec, "points", problems, f"links.{lname}"),
                     guides=_table(spec, "guides", problems, f"links.{lname}"),
                     mass=spec.get("mass"), com=_com(spec.get("com")), inertia=spec.get("inertia"))
    for pname, spec in _table(data, "pairs", problems).items():
        if not _add_pair(builder, pname, spec, problems):
            builder.reject(pname)
    inputs = data.get("inputs", data.get("input"))
    if isinstance(inputs, str):
        inputs = [inputs]
    if inputs is not None and not (isinstance(inputs, list) and all(isinstance(x, str) for x in inputs)):
        problems.append(f"input: expected a link name or a list of names, got {inputs!r}")
        inputs = None
    builder.inputs(*(inputs or []))
    for link, spec in _table(data, "input_laws", problems).items():
        _add_input_law(builder, link, spec, problems)
    for point, spec in _table(data, "assembly", problems).items():
        _add_assembly(builder, point, spec, problems)
    output = data.get("output")
    if output is not None:
        if isinstance(output, str):
            builder.output(output)
        elif isinstance(output, Mapping) and isinstance(output.get("quantity"), str):
            unknown_keys(output, {"quantity", "start"}, "output", problems)
            builder.output(output["quantity"], output.get("start", "max"))
        else:
            problems.append(f"output: expected \"P.x\" or {{quantity, start}}, got {output!r}")
    span = _input_range(data, problems)
    if span is not None:
        key = "range_deg" if "range_deg" in data else "range"
        builder.input_range(*span, degrees=key == "range_deg", given=f"{key} = {data[key]!r}")
    try:
        mech = builder.build(**extra_sections)
    except SchemeError as exc:
        raise SchemeError(problems + exc.problems) from None
    if problems:
        raise SchemeError(problems)
    for check in LOAD_CHECKS:
        check(mech, data)
    for section in _section_order():
        if section not in mech.parts:
            value, found = SECTION_PARSERS[section](mech, extra_sections.get(section))
            problems += [f"{section}: {p}" for p in found]
            if not found:
                mech.parts[section] = value
    if problems:
        raise SchemeError(problems)
    return mech


def _input_range(data: Mapping[str, Any], problems: list[str]) -> tuple[float, float] | None:
    """The input range ``range_deg = [a, b]`` (or ``range``: rad for an input angle, m for a
    slide's stroke) in rad or m; None when absent or refused (with the problem, naming the key and
    the value). Its span is checked against the input's kind when the mechanism is built."""
    if "range" in data and "range_deg" in data:
        problems.append("give either 'range' (rad) or 'range_deg' (deg), not both ('range' is in m for a slide "
                        "input)")
        return None
    key = "range_deg" if "range_deg" in data else "range" if "range" in data else None
    if key is None:
        return None
    raw = data[key]
    largest = MAX_ANGLE_DEG if key == "range_deg" else MAX_MAGNITUDE
    unit = "deg" if key == "range_deg" else "rad (m for a slide input)"
    if not (isinstance(raw, list) and len(raw) == 2 and all(is_number(v) and abs(v) <= largest for v in raw)):
        problems.append(f"{key}: expected [a, b], two input coordinates in {unit} with |x| <= {largest:.6g} "
                        f"(the input goes from a to b), got {raw!r}")
        return None
    return tuple(math.radians(v) for v in raw) if key == "range_deg" else (float(raw[0]), float(raw[1]))


def _table(data, key, problems, where="") -> dict:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        problems.append(f"{where + '.' if where else ''}{key}: expected a table, got {value!r}")
        return {}
    return dict(value)


def _declared_names(spec: Mapping[str, Any]) -> list:
    """The point and guide names a raw link table declares (its line, points and guides)."""
    names = list(spec.get("line", [])) if isinstance(spec.get("line"), list) else []
    for key in ("points", "guides"):
        if isinstance(spec.get(key), Mapping):
            names += list(spec[key])
    return names


def _com(raw):
    return tuple(raw) if isinstance(raw, list) else raw


def _add_pair(builder, name, spec, problems, link_names=None) -> bool:
    """Declare the pair ``name`` on the builder; False (with the problem) when it is refused."""
    where = f"pairs.{name}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table, got {spec!r}")
        return False
    if unknown_keys(spec, PAIR_KEYS, where, problems) or (set(spec) - PAIR_KEYS and "links" not in spec):
        return False  # a misspelt key: the pair is incomplete, say so once
    raw_kind = spec.get("kind", "R")
    kind = PAIR_KINDS.get(raw_kind) if isinstance(raw_kind, str) else None
    links = spec.get("links")
    if kind is None:
        problems.append(f"{where}: kind must be 'R' (revolute) or 'P' (prismatic), got {raw_kind!r}")
        return False
    if not (isinstance(links, list) and len(links) == 2 and all(isinstance(x, str) for x in links)):
        problems.append(f"{where}: 'links' must name two links, got {links!r}")
        return False
    if "at" in spec and not isinstance(spec["at"], str):
        problems.append(f"{where}: 'at' must name a point, got {spec['at']!r}")
        return False
    if kind == "R":
        builder.revolute(name, links[0], links[1], spec.get("at"))
        return True
    if not isinstance(spec.get("guide"), str) or not isinstance(spec.get("at"), str):
        problems.append(f"{where}: a prismatic pair needs 'guide' (a guide of link '{links[0]}') and "
                        f"'at' (a point of slider link '{links[1]}')")
        return False
    count = len(problems)
    angle = angle_from(spec, "angle", where, problems)
    if len(problems) > count:
        return False
    builder.prismatic(name, links[0], links[1], guide=spec["guide"], at=spec["at"], angle=angle)
    return True


def _add_assembly(builder, point, spec, problems):
    where = f"assembly.{point}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table such as {{left_of = [\"A\", \"C\"]}}, got {spec!r}")
        return
    known = {"left_of", "right_of", "towards", "towards_deg", "from", "branch", "mode", "phi", "phi_deg"}
    if unknown_keys(spec, known, where, problems):
        return  # one message: the misspelt key, not the condition it leaves incomplete
    count = len(problems)
    towards = angle_from(spec, "towards", where, problems, default=None)
    phi = angle_from(spec, "phi", where, problems, default=None)
    if len(problems) > count:
        return
    builder.assembly(point, left_of=spec.get("left_of"), right_of=spec.get("right_of"),
                     towards=towards, origin=spec.get("from"), branch=spec.get("branch"),
                     mode=spec.get("mode", "keep"), phi=phi)


def _add_input_law(builder, link, spec, problems):
    """``[input_laws.K]``: ``ratio`` and ``phase_deg`` (or ``phase``, rad), or ``table_deg`` (or
    ``table``, rad): pairs ``[phi, theta]`` of the first input's angle and link K's."""
    where = f"input_laws.{link}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table such as {{ratio = -1, phase_deg = 90}}, got {spec!r}")
        return
    if unknown_keys(spec, {"ratio", "phase", "phase_deg", "table", "table_deg"}, where, problems):
        return
    count = len(problems)
    phase = angle_from(spec, "phase", where, problems, default=None)
    if "table" in spec and "table_deg" in spec:
        problems.append(f"{where}: give either 'table' (rad) or 'table_deg' (deg), not both")
    if len(problems) > count:
        return
    raw = spec.get("table_deg", spec.get("table"))
    table = None
    if raw is not None:
        key = "table_deg" if "table_deg" in spec else "table"
        if not (isinstance(raw, list) and all(isinstance(row, list) and len(row) == 2 and all(map(is_number, row))
                                              for row in raw)):
            problems.append(f"{where}: {key} must be a list of pairs [phi, theta] of numbers, got {raw!r}")
            return
        scale = math.pi / 180 if key == "table_deg" else 1.0
        table = ([row[0] * scale for row in raw], [row[1] * scale for row in raw])
    builder.input_law(link, ratio=spec.get("ratio"), phase=phase, table=table,
                      degrees=[key for key in ("phase_deg", "table_deg") if key in spec])


# ----------------------------------------------------------------------------------------------
# writing
# ----------------------------------------------------------------------------------------------


def to_dict(mech: Mechanism) -> dict[str, Any]:
    """The scheme of ``mech`` as plain data (local coordinates, angles in rad)."""
    data: dict[str, Any] = {"name": mech.name}
    if mech.description:
        data["description"] = mech.description
    data["frame"] = mech.frame
    data["inputs"] = list(mech.inputs)
    if mech.output is not None:
        data["output"] = {"quantity": mech.output.quantity, "start": mech.output.start}
    if mech.input_range is not None:
        data["range"] = list(mech.input_range)
    if mech.input_laws:
        data["input_laws"] = {link: {"table": [list(row) for row in zip(*law.table)]} if law.table is not None
                              else {"ratio": law.ratio, "phase": law.phase} for link, law in mech.input_laws.items()}
    data["links"] = {}
    for name in sorted(mech.links):
        link = mech.links[name]
        spec: dict[str, Any] = {"points": {p: list(v) for p, v in link.points.items()}}
        if link.guides:
            spec["guides"] = {g: {"through": list(gd.point), "angle": gd.angle} for g, gd in link.guides.items()}
        if link.mass_declared:
            spec["mass"] = link.mass
        spec["com"] = list(link.center_of_mass)
        spec["inertia"] = link.inertia
        data["links"][name] = spec
    data["pairs"] = {}
    for name in sorted(mech.pairs):
        pair = mech.pairs[name]
        if isinstance(pair, Revolute):
            data["pairs"][name] = {"kind": "R", "links": list(pair.links), "at": pair.point}
        elif isinstance(pair, Prismatic):
            data["pairs"][name] = {"kind": "P", "links": list(pair.links), "guide": pair.guide,
                                   "at": pair.point, "angle": pair.angle}
    if mech.assembly:
        data["assembly"] = {}
        for rule in mech.assembly:
            if rule.rule == "branch":
                entry = {"branch": rule.value}
            elif rule.rule == "towards":
                entry = {"towards": rule.angle, "from": rule.refs[0]}
            else:
                entry = {rule.rule: list(rule.refs)}
            if rule.mode != "keep":
                entry["mode"] = rule.mode
            if rule.phi is not None:
                entry["phi"] = rule.phi
            data["assembly"][rule.point] = entry
    data.update(copy.deepcopy(dict(mech.extra)))
    return data


def dumps(mech: Mechanism) -> str:
    """TOML text of a mechanism that :func:`loads` reads back to an equal mechanism."""
    return toml_text(to_dict(mech))


def toml_text(data: Mapping[str, Any]) -> str:
    """TOML text of plain data (tables, arrays of tables, numbers, strings, lists) that
    ``tomllib.loads`` reads back equal; floats are written with ``repr`` (exact)."""
    return _toml_table(data, ())


def save(mech: Mechanism, path: str | Path) -> None:
    """Write a mechanism to a scheme file."""
    Path(path).write_text(dumps(mech), encoding="utf-8")


_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE.match(k) else _string(k)


def _string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        if isinstance(v, float) and not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise SchemeError(f"cannot write {v!r} to TOML (only numbers, strings, lists and tables)")


def _toml_table(data: Mapping[str, Any], path: tuple[str, ...], array: bool = False) -> str:
    """TOML text of a table at ``path`` (an element of an array of tables when ``array``)."""
    lines, tables, arrays = [], [], []
    for k, v in data.items():
        if isinstance(v, Mapping) and v and (len(path) < 2 or all(isinstance(x, Mapping) for x in v.values())):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, Mapping) for x in v):
            arrays.append((k, v))
        else:
            lines.append(f"{_key(k)} = {_value(v)}")
    out = []
    if path and (lines or array or not (tables or arrays)):
        dotted = ".".join(_key(p) for p in path)
        out.append(f"[[{dotted}]]" if array else f"[{dotted}]")
    out += lines
    for k, v in tables:
        out += ["", _toml_table(v, (*path, k)).rstrip()]
    for k, items in arrays:
        for item in items:
            out += ["", _toml_table(item, (*path, k), array=True).rstrip()]
    return "\n".join(out).lstrip("\n") + "\n"
