"""Scheme files: read, validate and write declarative mechanisms (TOML).

The format is documented with a complete annotated example in ``schemes/README.md``.

>>> import linkage
>>> mech = linkage.load("four_bar")
>>> linkage.loads(linkage.dumps(mech)) == mech
True
"""

from __future__ import annotations

import copy
import importlib.resources
import math
import re
import tomllib
from pathlib import Path
from typing import Any, Callable, Mapping

from .errors import SchemeError, StructureError
from .model import Mechanism, MechanismBuilder, Prismatic, Revolute, _is_number

__all__ = ["load", "loads", "dumps", "save", "shipped_schemes", "scheme_path", "SECTION_VALIDATORS"]

TOP_KEYS = {"name", "description", "frame", "input", "inputs", "output", "links", "pairs", "assembly"}
LINK_KEYS = {"line", "length", "points", "guides", "mass", "com", "inertia"}
PAIR_KEYS = {"kind", "links", "at", "guide", "angle", "angle_deg"}
PAIR_KINDS = {"R": "R", "revolute": "R", "P": "P", "prismatic": "P"}

#: Further top-level sections (``loads``, ``dynamics`` ...): name -> validator returning a list of
#: problems for (mechanism, raw section). Registered by the modules that use them.
SECTION_VALIDATORS: dict[str, Callable[[Mechanism, Any], list[str]]] = {}


def _schemes_dirs() -> list[Path]:
    dirs = []
    try:
        dirs.append(Path(str(importlib.resources.files("linkage.schemes"))))
    except (ModuleNotFoundError, TypeError):
        pass
    dirs.append(Path(__file__).resolve().parent.parent / "schemes")
    return [d for d in dirs if d.is_dir()]


def shipped_schemes() -> dict[str, Path]:
    """Shipped scheme names -> files, sorted by name."""
    found: dict[str, Path] = {}
    for d in _schemes_dirs():
        for f in sorted(d.glob("*.toml")):
            found.setdefault(f.stem, f)
    return dict(sorted(found.items()))


def scheme_path(name_or_path: str | Path) -> Path:
    """The file of a shipped scheme name, or the given path."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise SchemeError(f"{path}: no such scheme file")
        return path
    shipped = shipped_schemes()
    if str(name_or_path) not in shipped:
        raise SchemeError(f"unknown scheme {str(name_or_path)!r}: not a file, and not a shipped "
                          f"scheme ({', '.join(shipped)})")
    return shipped[str(name_or_path)]


def load(name_or_path: str | Path) -> Mechanism:
    """Load a shipped scheme by name (``"slider_crank"``) or any scheme file by path.

    Raises
    ------
    SchemeError
        Listing every problem, each prefixed with the file name.
    """
    path = scheme_path(name_or_path)
    return loads(path.read_text(encoding="utf-8"), source=str(path), default_name=path.stem)


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
    """Build and validate a mechanism from a parsed scheme (structure included)."""
    from .kinematics import assembly_branches, structure_of

    problems: list[str] = []
    extra_sections = {k: v for k, v in data.items() if k in SECTION_VALIDATORS}
    unknown = set(data) - TOP_KEYS - set(SECTION_VALIDATORS)
    if unknown:
        problems.append(f"unknown top-level keys {sorted(unknown)} (known: "
                        f"{sorted(TOP_KEYS | set(SECTION_VALIDATORS))})")
    name = data.get("name", default_name)
    builder = MechanismBuilder(str(name), str(data.get("description", "")), str(data.get("frame", "0")))
    links = _table(data, "links", problems)
    for lname, spec in links.items():
        if not isinstance(spec, Mapping):
            problems.append(f"links.{lname}: expected a table, got {spec!r}")
            continue
        bad = set(spec) - LINK_KEYS
        if bad:
            problems.append(f"links.{lname}: unknown keys {sorted(bad)} (known: {sorted(LINK_KEYS)})")
        line = spec.get("line")
        builder.link(lname, line=tuple(line) if isinstance(line, list) else line, length=spec.get("length"),
                     points=_table(spec, "points", problems, f"links.{lname}"),
                     guides=_table(spec, "guides", problems, f"links.{lname}"),
                     mass=spec.get("mass"), com=_com(spec.get("com")), inertia=spec.get("inertia"))
    for pname, spec in _table(data, "pairs", problems).items():
        _add_pair(builder, pname, spec, problems, set(links) | {builder.frame})
    inputs = data.get("inputs", data.get("input"))
    if isinstance(inputs, str):
        inputs = [inputs]
    if inputs is not None and not (isinstance(inputs, list) and all(isinstance(x, str) for x in inputs)):
        problems.append(f"input: expected a link name or a list of names, got {inputs!r}")
        inputs = None
    builder.inputs(*(inputs or []))
    for point, spec in _table(data, "assembly", problems).items():
        _add_assembly(builder, point, spec, problems)
    output = data.get("output")
    if output is not None:
        if isinstance(output, str):
            builder.output(output)
        elif isinstance(output, Mapping) and isinstance(output.get("quantity"), str):
            builder.output(output["quantity"], output.get("start", "max"))
        else:
            problems.append(f"output: expected \"P.x\" or {{quantity, start}}, got {output!r}")
    try:
        mech = builder.build(**extra_sections)
    except SchemeError as exc:
        raise SchemeError(problems + exc.problems) from None
    for section, raw in extra_sections.items():
        problems += [f"{section}: {p}" for p in SECTION_VALIDATORS[section](mech, raw)]
    if problems:
        raise SchemeError(problems)
    try:
        structure_of(mech)
        assembly_branches(mech)
    except StructureError as exc:
        raise SchemeError(str(exc)) from None
    return mech


def _table(data, key, problems, where="") -> dict:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        problems.append(f"{where + '.' if where else ''}{key}: expected a table, got {value!r}")
        return {}
    return dict(value)


def _com(raw):
    return tuple(raw) if isinstance(raw, list) else raw


def _add_pair(builder, name, spec, problems, link_names):
    where = f"pairs.{name}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table, got {spec!r}")
        return
    bad = set(spec) - PAIR_KEYS
    if bad:
        problems.append(f"{where}: unknown keys {sorted(bad)} (known: {sorted(PAIR_KEYS)})")
    kind = PAIR_KINDS.get(spec.get("kind", "R"))
    links = spec.get("links")
    if kind is None:
        problems.append(f"{where}: kind must be 'R' (revolute) or 'P' (prismatic), got {spec.get('kind')!r}")
        return
    if not (isinstance(links, list) and len(links) == 2 and all(isinstance(x, str) for x in links)):
        problems.append(f"{where}: 'links' must name two links, got {links!r}")
        return
    if kind == "R":
        builder.revolute(name, links[0], links[1], spec.get("at"))
        return
    if not isinstance(spec.get("guide"), str) or not isinstance(spec.get("at"), str):
        problems.append(f"{where}: a prismatic pair needs 'guide' (a guide of link '{links[0]}') and "
                        f"'at' (a point of slider link '{links[1]}')")
        return
    angle = 0.0
    if "angle" in spec or "angle_deg" in spec:
        raw = spec.get("angle", spec.get("angle_deg"))
        if not _is_number(raw):
            problems.append(f"{where}: angle must be a number, got {raw!r}")
        else:
            angle = float(raw) if "angle" in spec else math.radians(raw)
    builder.prismatic(name, links[0], links[1], guide=spec["guide"], at=spec["at"], angle=angle)


def _add_assembly(builder, point, spec, problems):
    where = f"assembly.{point}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: expected a table such as {{left_of = [\"A\", \"C\"]}}, got {spec!r}")
        return
    known = {"left_of", "right_of", "towards", "towards_deg", "from", "branch"}
    bad = set(spec) - known
    if bad:
        problems.append(f"{where}: unknown keys {sorted(bad)} (known: {sorted(known)})")
    towards = spec.get("towards")
    if "towards_deg" in spec:
        towards = math.radians(spec["towards_deg"]) if _is_number(spec["towards_deg"]) else spec["towards_deg"]
    builder.assembly(point, left_of=spec.get("left_of"), right_of=spec.get("right_of"),
                     towards=towards, origin=spec.get("from"), branch=spec.get("branch"))


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
                data["assembly"][rule.point] = {"branch": rule.value}
            elif rule.rule == "towards":
                data["assembly"][rule.point] = {"towards": rule.angle, "from": rule.refs[0]}
            else:
                data["assembly"][rule.point] = {rule.rule: list(rule.refs)}
    data.update(copy.deepcopy(dict(mech.extra)))
    return data


def dumps(mech: Mechanism) -> str:
    """TOML text of a mechanism that :func:`loads` reads back to an equal mechanism."""
    return _toml_table(to_dict(mech), ())


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
    raise TypeError(f"cannot write {v!r} to TOML")


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
