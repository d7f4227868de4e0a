"""What a student is given: one variant's data, machine-readable (``given.json``), and the rows of
the sheet printed from it.

:func:`given_data` -- the variant's ``given.json`` as plain data: the variant's label and folder,
the template's name, description and tasks, the parameters table, the variant's **whole scheme**
(``"scheme"``: the parsed ``scheme.toml``, every number the answer key depends on) and, next to
it, the same data in a student's words: the sections of the data table (``"data"``: rows of
quantity, symbol, value and unit, each naming the scheme entries it shows in ``"from"``) and the
load diagrams with their tables and zones (``"diagrams"``). No path and no time: the same variant
gives the same file. :func:`given_json` writes it; :func:`scheme_from_given` rebuilds the
mechanism from it alone and :func:`grading_from_given` the key's grading (the key of the rebuilt
mechanism is the variant's, exactly);
:func:`sheet_rows` lists every row a sheet prints from it (:mod:`~linkage.course.sheets` draws
them), and :func:`scheme_leaves` every datum of its scheme, so that a test can check that
nothing the key uses is missing from the sheet.

Symbols are mathtext (``"$J_{S2}$"``, matplotlib's TeX subset), units and words plain Unicode
(``kg·m²``, ``φ``, ``δ``, ``I₀``).

>>> import linkage
>>> from linkage.model.scheme import dumps
>>> mech = linkage.load("course_slider_crank")
>>> rows = data_sections(tomllib.loads(dumps(mech)), {})
>>> [s["title"] for s in rows][:2]
['Links: dimensions', 'Masses and moments of inertia']
>>> number_text(-9.81), number_text(31250.0), unit_text("kg m^2")
('−9.81', '31250', 'kg·m²')
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import InputError, SchemeError
from ..model.mechanism import Mechanism
from ..model.scheme import from_dict
from ..report.results import declared_rotation, table_defaults, table_positions
from ..report.words import unit_for_people
from .key import default_points
from .template import Grading

__all__ = ["GIVEN_FORMAT", "given_data", "given_json", "scheme_from_given", "data_sections", "load_diagrams",
           "sheet_rows", "scheme_leaves", "number_text", "unit_text", "zone_text", "subscripted", "FURTHER", "PARAMETERS", "GRADING",
           "grading_from_given", "grading_section"]

#: the format of ``given.json`` (its ``"format"`` entry)
GIVEN_FORMAT = "linkage given.json 1"
#: rad/s per rpm
RPM = 2 * math.pi / 60
#: titles of the data table's sections, in the order printed
GEOMETRY, MASSES, PAIRS, MOTION, LOADS, SPEED, FRICTION = (
    "Links: dimensions", "Masses and moments of inertia", "Kinematic pairs", "Input, output and position 1",
    "Loads", "Speed, flywheel and motor", "Friction in the pairs")
#: the section of what is graded and how
GRADING = "What you report and how it is graded"
#: the section of the template's parameters on a sheet
PARAMETERS = "Parameters of the variant"
#: the section of scheme entries no other row shows (a scheme key this module does not word)
FURTHER = "Further data of the scheme"
#: top-level scheme entries that are not data (the sheet's title and description say them)
NOT_DATA = ("name", "description")

#: units written otherwise in print than :func:`~linkage.report.words.unit_for_people` writes them
_UNITS = {"deg": "°", "1/s": "s⁻¹", "kg m2": "kg·m²", "Nm": "N·m"}


# ----------------------------------------------------------------------------------------------
# words for numbers, units and symbols
# ----------------------------------------------------------------------------------------------


def number_text(value: Any, digits: int = 12) -> str:
    """A number as a student reads it: up to ``digits`` significant digits, no trailing ``.0``,
    a real minus sign; ``True``/``False`` as yes/no, a string as it is.

    >>> number_text(0.30000000000000004), number_text(-110), number_text(1e-7)
    ('0.3', '−110', '1e−07')
    """
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        text = str(int(value))
    elif isinstance(value, (float, np.floating)):
        text = f"{float(value):.{digits}g}"
    else:
        return str(value)
    return text.replace("-", "−")


def unit_text(unit: str) -> str:
    """A unit in print: ``kg m^2`` -> ``kg·m²``, ``m/s^2`` -> ``m/s²``, ``N m`` -> ``N·m``."""
    unit = str(unit or "").strip()
    return _UNITS.get(unit) or unit_for_people(unit) or ""


_SUBSCRIPTS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def subscripted(name: str) -> str:
    """``"F1"`` -> ``"F₁"``: the digits after the first letter as subscripts."""
    return name[:1] + name[1:].translate(_SUBSCRIPTS)


def _pair(values: Sequence[Any]) -> str:
    return "(" + ", ".join(number_text(v) for v in values) + ")"


def _sub(name: str) -> str:
    """``name`` as a mathtext subscript body (letters and digits only; others escaped away)."""
    return re.sub(r"[^A-Za-z0-9]", "", str(name))


def _symbol(letter: str, sub: str = "") -> str:
    sub = _sub(sub)
    return f"${letter}_{{{sub}}}$" if sub else f"${letter}$"


def _angle(spec: Mapping[str, Any], key: str) -> tuple[str, str, str] | None:
    """(text, unit, source key) of an angle given as ``key_deg`` (deg) or ``key`` (rad)."""
    if f"{key}_deg" in spec:
        return number_text(spec[f"{key}_deg"]), "°", f"{key}_deg"
    if key in spec:
        return number_text(spec[key]), "rad", key
    return None


# ----------------------------------------------------------------------------------------------
# the rows of the data table
# ----------------------------------------------------------------------------------------------


class _Rows:
    """Sections of rows, in the order of :data:`_ORDER`."""

    _ORDER = (GEOMETRY, MASSES, PAIRS, MOTION, LOADS, SPEED, FRICTION, FURTHER)

    def __init__(self):
        self.sections: dict[str, list[dict[str, Any]]] = {title: [] for title in self._ORDER}

    def add(self, section: str, quantity: str, symbol: str, value: str, unit: str = "",
            sources: Sequence[str] = ()) -> None:
        self.sections[section].append({"quantity": quantity, "symbol": symbol, "value": value,
                                       "unit": unit_text(unit), "from": list(sources)})

    def result(self) -> list[dict[str, Any]]:
        return [{"title": title, "rows": rows} for title, rows in self.sections.items() if rows]


def _who(name: str, frame: str) -> str:
    return "the frame" if name == frame else f"link {name}"


def _point_rows(rows: _Rows, who: str, base: str, point: str, spec: Any, axis: str) -> None:
    where = f"{base}.points.{point}"
    if isinstance(spec, list):
        frame_words = "global coordinates" if who == "the frame" else f"in the frame of {who}{axis}"
        rows.add(GEOMETRY, f"point {point} of {who}: (x, y), {frame_words}", "", _pair(spec), "m", [where])
        return
    if isinstance(spec, Mapping):
        origin = spec.get("from", "?")
        rows.add(GEOMETRY, f"point {point} of {who}: its distance from {origin}", _symbol("l", f"{origin}{point}"),
                 number_text(spec.get("distance")), "m", [f"{where}.from", f"{where}.distance"])
        angle = _angle(spec, "angle")
        if angle is not None:
            text, unit, key = angle
            rows.add(GEOMETRY, f"point {point} of {who}: the direction {origin} → {point}, counter-clockwise from "
                     f"the x axis of {who}{axis}", "", text, unit, [f"{where}.{key}"])
        else:
            rows.add(GEOMETRY, f"point {point} of {who}: the direction {origin} → {point}", "",
                     f"along the x axis of {who}{axis}")


def _guide_rows(rows: _Rows, who: str, base: str, guide: str, spec: Any, axis: str) -> None:
    where = f"{base}.guides.{guide}"
    if not isinstance(spec, Mapping):
        return
    through = spec.get("through")
    if isinstance(through, list):
        frame_words = "global coordinates" if who == "the frame" else f"in the frame of {who}"
        rows.add(GEOMETRY, f"guide ‘{guide}’ of {who}: passes through (x, y), {frame_words}", "", _pair(through),
                 "m", [f"{where}.through"])
    elif through is not None:
        rows.add(GEOMETRY, f"guide ‘{guide}’ of {who}: passes through the point", "", str(through), "",
                 [f"{where}.through"])
    angle = _angle(spec, "angle")
    text, unit, key = angle if angle is not None else ("0", "°", None)
    rows.add(GEOMETRY, f"guide ‘{guide}’ of {who}: its direction, counter-clockwise from the x axis of {who}{axis}",
             "", text, unit, [f"{where}.{key}"] if key else [])
    if "offset" in spec:
        rows.add(GEOMETRY, f"guide ‘{guide}’ of {who}: shifted along its left normal by", "",
                 number_text(spec["offset"]), "m", [f"{where}.offset"])


def _link_rows(rows: _Rows, scheme: Mapping[str, Any]) -> None:
    frame = str(scheme.get("frame", "0"))
    for name, spec in scheme.get("links", {}).items():
        if not isinstance(spec, Mapping):
            continue
        base, who = f"links.{name}", _who(name, frame)
        line = spec.get("line")
        axis = ""
        if isinstance(line, list) and len(line) == 2:
            p, q = line
            axis = f" ({p} → {q})"
            rows.add(GEOMETRY, f"length {p}{q} of {who} (its x axis runs {p} → {q})", _symbol("l", f"{p}{q}"),
                     number_text(spec.get("length")), "m", [f"{base}.line", f"{base}.length"])
        for point, value in spec.get("points", {}).items():
            _point_rows(rows, who, base, point, value, axis)
        for guide, value in spec.get("guides", {}).items():
            _guide_rows(rows, who, base, guide, value, axis)
        if name == frame and not any(k in spec for k in ("mass", "com", "inertia")):
            continue
        mass = spec.get("mass")
        rows.add(MASSES, f"mass of {who}", _symbol("m", name),
                 number_text(mass) if mass is not None else "0 (massless)", "kg",
                 [f"{base}.mass"] if mass is not None else [])
        com = spec.get("com")
        if isinstance(com, list):
            rows.add(MASSES, f"centre of mass of {who}: (x, y) in its frame{axis}", _symbol("S", name), _pair(com),
                     "m", [f"{base}.com"])
        elif com is not None:
            rows.add(MASSES, f"centre of mass of {who}", _symbol("S", name), f"at the point {com}", "",
                     [f"{base}.com"])
        inertia = spec.get("inertia")
        rows.add(MASSES, f"moment of inertia of {who} about its centre of mass", _symbol("J", f"S{name}"),
                 number_text(inertia) if inertia is not None else "0", "kg m^2",
                 [f"{base}.inertia"] if inertia is not None else [])


def _pair_rows(rows: _Rows, scheme: Mapping[str, Any]) -> None:
    for name, spec in scheme.get("pairs", {}).items():
        if not isinstance(spec, Mapping):
            continue
        base = f"pairs.{name}"
        kind = spec.get("kind", "R")
        links = spec.get("links", ["?", "?"])
        sources = [f"{base}.links"] + ([f"{base}.kind"] if "kind" in spec else [])
        if str(kind).upper().startswith("P"):
            guide, at = spec.get("guide", "?"), spec.get("at", "?")
            text = (f"sliding pair ({kind}): link {links[1]} slides with its point {at} along the guide ‘{guide}’ "
                    f"of link {links[0]}")
            rows.add(PAIRS, f"pair {name}", "", text, "", [*sources, f"{base}.guide", f"{base}.at"])
            angle = _angle(spec, "angle")
            if angle is not None:
                value, unit, key = angle
                rows.add(PAIRS, f"pair {name}: the angle of link {links[1]}'s x axis to the guide", "", value, unit,
                         [f"{base}.{key}"])
        else:
            at = spec.get("at", name)
            text = f"turning pair ({kind}) of links {links[0]} and {links[1]} at their point {at}"
            rows.add(PAIRS, f"pair {name}", "", text, "", [*sources, *([f"{base}.at"] if "at" in spec else [])])


_START_WORDS = {"max": "at its maximum (max)", "min": "at its minimum (min)"}


def _output(scheme: Mapping[str, Any]) -> tuple[str | None, str]:
    output = scheme.get("output")
    if isinstance(output, str):
        return output, "max"
    if isinstance(output, Mapping):
        return output.get("quantity"), output.get("start", "max")
    return None, "max"


def _motion_rows(rows: _Rows, scheme: Mapping[str, Any], facts: Mapping[str, Any]) -> None:
    if "frame" in scheme:
        rows.add(MOTION, "the frame (the fixed link)", "", str(scheme["frame"]), "", ["frame"])
    key = "inputs" if "inputs" in scheme else "input"
    inputs = scheme.get(key)
    names = inputs if isinstance(inputs, list) else [inputs]
    rows.add(MOTION, "input link (its x axis turns by the input angle φ)" if len(names) == 1 else
             "input links (the first one's angle is φ)", "", ", ".join(str(n) for n in names), "", [key])
    for link, law in scheme.get("input_laws", {}).items():
        base = f"input_laws.{link}"
        for k, v in law.items():
            if k in ("table", "table_deg"):
                unit = "°" if k == "table_deg" else "rad"
                for i, (a, b) in enumerate(v):
                    rows.add(MOTION, f"input link {link}: table row {i + 1} (φ, θ{_sub(link)})", "", _pair([a, b]),
                             unit, [f"{base}.{k}.{i}"])
            else:
                words = {"ratio": ("ratio of θ to φ (θ = ratio·φ + phase)", ""), "phase_deg": ("phase", "°"),
                         "phase": ("phase", "rad")}.get(k, (k, ""))
                rows.add(MOTION, f"input link {link}: {words[0]}", "", number_text(v), words[1], [f"{base}.{k}"])
    for key, unit in (("range_deg", "°"), ("range", "rad or m")):
        if key in scheme:
            rows.add(MOTION, "the input runs over (from, to)", "", _pair(scheme[key]), unit, [key])
    quantity, start = _output(scheme)
    if quantity is not None:
        sources = ["output"] if isinstance(scheme.get("output"), str) else ["output.quantity"]
        rows.add(MOTION, "output coordinate", "", str(quantity), "", sources)
        rows.add(MOTION, "position 1 of the cycle: the output", "", _START_WORDS.get(start, str(start)), "",
                 ["output.start"] if isinstance(scheme.get("output"), Mapping) and "start" in scheme["output"] else [])
    for point, spec in scheme.get("assembly", {}).items():
        base = f"assembly.{point}"
        parts, sources = [], []
        for side in ("left_of", "right_of"):
            if side in spec:
                x, y = spec[side]
                parts.append(f"{point} lies to the {side.split('_')[0]} of the line {x} → {y}")
                sources.append(f"{base}.{side}")
        if "from" in spec:
            angle = _angle(spec, "towards")
            text, unit, key = angle if angle is not None else ("?", "", "towards")
            parts.append(f"{point} lies from {spec['from']} towards {text}{unit if unit == '°' else ' ' + unit}")
            sources += [f"{base}.from", f"{base}.{key}"]
        if "branch" in spec:
            parts.append(f"{point} on the solver's branch {number_text(spec['branch'])}")
            sources.append(f"{base}.branch")
        angle = _angle(spec, "phi")
        if angle is not None:
            text, unit, key = angle
            parts.append(f"at the input angle φ = {text}{unit if unit == '°' else ' ' + unit}")
            sources.append(f"{base}.{key}")
        if "mode" in spec:
            parts.append(f"mode at change points: {spec['mode']}")
            sources.append(f"{base}.mode")
        rows.add(MOTION, f"assembly of the group with the point {point}", "", "; ".join(parts), "", sources)
    if "phi1_deg" in facts:
        rows.add(MOTION, f"position 1 ({facts.get('position_1', 'as declared')}): the input angle from the x axis",
                 _symbol("\\varphi", "1"), number_text(facts["phi1_deg"], 6), "°")
    if "s1" in facts:
        rows.add(MOTION, f"position 1 ({facts.get('position_1', 'as declared')}): the input slide", _symbol("s", "1"),
                 number_text(facts["s1"], 6), "m")


def _force_link(scheme: Mapping[str, Any], point: str) -> str:
    """The moving link that holds ``point`` when a force names none (the scheme names it when several do)."""
    frame = str(scheme.get("frame", "0"))
    for name, spec in scheme.get("links", {}).items():
        if name != frame and isinstance(spec, Mapping) and (point in spec.get("points", {}) or
                                                             point in (spec.get("line") or [])):
            return name
    return "?"


def _stroke_words(diagram: Mapping[str, Any], quantity: str) -> str:
    working = diagram.get("working")
    sense = "increasing" if working in ("+", 1) else "decreasing"
    return f"{quantity} {sense} ({'+' if working in ('+', 1) else '−'})"


def _diagram_rows(rows: _Rows, name: str, base: str, diagram: Mapping[str, Any], quantity: str,
                  signed: bool) -> None:
    rows.add(LOADS, f"{name}: its diagram over the working stroke of", "", str(quantity), "",
             [f"{base}.quantity"] if "quantity" in diagram else [])
    rows.add(LOADS, f"{name}: the working stroke is the half-cycle with", "", _stroke_words(diagram, quantity), "",
             [f"{base}.working"])
    if not signed:
        opposes = diagram.get("opposes", True)
        rows.add(LOADS, f"{name} opposes the motion (a useful resistance)", "",
                 "yes" if opposes else "no: it drives the motion", "",
                 [f"{base}.opposes"] if "opposes" in diagram else [])
    idle = "the diagram below" if "idle_fractions" in diagram else "no load (0)"
    rows.add(LOADS, f"{name} on the idle stroke", "", idle, "")
    rows.add(LOADS, f"{name}: its values at the fractions t of the stroke", "", "see the load diagrams", "")


def _load_rows(rows: _Rows, scheme: Mapping[str, Any]) -> None:
    loads = scheme.get("loads", {})
    if "gravity" in loads:
        rows.add(LOADS, "acceleration of gravity (gx, gy), at every centre of mass", "$g$", _pair(loads["gravity"]),
                 "m/s^2", ["loads.gravity"])
    else:
        rows.add(LOADS, "acceleration of gravity (gx, gy), at every centre of mass", "$g$", _pair([0.0, -9.81]),
                 "m/s^2")
    for k, spec in enumerate(loads.get("forces", []), start=1):
        base, name = f"loads.forces.{k - 1}", subscripted(f"F{k}")
        point = spec.get("point", "?")
        link = spec.get("link")
        rows.add(LOADS, f"force {name}: acts at the point", _symbol("F", str(k)),
                 f"{point} of link {link if link is not None else _force_link(scheme, point)}", "",
                 [f"{base}.point", *([f"{base}.link"] if link is not None else [])])
        if "between" in spec:
            p, q = spec["between"]
            rows.add(LOADS, f"{name} acts along the line through two points", "",
                     f"{p} → {q} (a positive value pushes from {p} towards {q})", "", [f"{base}.between"])
        if "along_link" in spec:
            angle = _angle(spec, "angle")
            text, unit, key = angle if angle is not None else ("0", "°", None)
            rows.add(LOADS, f"{name} acts along a direction fixed in link {spec['along_link']}, counter-clockwise "
                     "from its x axis by", "", text, unit, [f"{base}.along_link", *([f"{base}.{key}"] if key else [])])
        directed = "between" in spec or "along_link" in spec
        if "force" in spec:
            rows.add(LOADS, f"{name} = (Fx, Fy), constant, global components", "", _pair(spec["force"]), "N",
                     [f"{base}.force"])
        if "magnitude" in spec:
            rows.add(LOADS, f"{name}: constant signed value along its direction", "", number_text(spec["magnitude"]),
                     "N", [f"{base}.magnitude"])
        if "along" in spec:
            rows.add(LOADS, f"{name} acts along the axis", "", str(spec["along"]), "", [f"{base}.along"])
        if "cycle" in spec:
            rows.add(LOADS, f"{name}: signed values at the table positions", "", "see the load diagrams", "N")
        if isinstance(spec.get("diagram"), Mapping):
            diagram = spec["diagram"]
            along = diagram.get("along")
            if along is not None:
                rows.add(LOADS, f"{name} acts along the axis", "", str(along), "", [f"{base}.diagram.along"])
            quantity = diagram.get("quantity") if directed else f"{point}.{along}"
            _diagram_rows(rows, name, f"{base}.diagram", diagram, str(quantity), signed=directed)
    for k, spec in enumerate(loads.get("moments", []), start=1):
        base, name = f"loads.moments.{k - 1}", subscripted(f"M{k}")
        link = spec.get("link", "?")
        rows.add(LOADS, f"moment {name} acts on link (counter-clockwise positive)", _symbol("M", str(k)), str(link),
                 "", [f"{base}.link"])
        if "moment" in spec:
            rows.add(LOADS, f"{name}, constant", "", number_text(spec["moment"]), "N m", [f"{base}.moment"])
        if isinstance(spec.get("diagram"), Mapping):
            _diagram_rows(rows, name, f"{base}.diagram", spec["diagram"], f"{link}.theta", signed=False)


_MOTOR_WORDS = {
    "moment": ("constant driving moment at the crank", "N m"), "stall_moment": ("moment at rest M₀ (motor shaft)", "N m"),
    "no_load_speed": ("no-load speed ω₀ (motor shaft)", "rad/s"), "no_load_rpm": ("no-load speed n₀ (motor shaft)", "rpm"),
    "ratio": ("gear ratio U = motor speed / crank speed", ""), "efficiency": ("efficiency of the gear η", ""),
    "synchronous_rpm": ("synchronous speed nₛ", "rpm"), "rated_rpm": ("rated speed n_nom", "rpm"),
    "rated_moment": ("rated moment M_nom", "N m"), "rated_power": ("rated power P", "W"),
    "overload": ("overload capacity λ = M_k / M_nom", ""),
}


def _friction_rows(rows: _Rows, scheme: Mapping[str, Any]) -> None:
    """``[friction]``: the coefficients and radii per class of pairs and per pair."""
    spec = scheme.get("friction")
    if not isinstance(spec, Mapping):
        return
    words = {"f": ("coefficient of friction", "f", ""), "radius": ("journal radius (friction circle f·r)", "r", "m"),
             "length": ("slider block length", "b", "m")}
    entries = [(key, f"every {key} pair", spec[key]) for key in ("revolute", "prismatic")
               if isinstance(spec.get(key), Mapping)]
    entries += [(f"pairs.{name}", f"pair {name}", value) for name, value in (spec.get("pairs") or {}).items()
                if isinstance(value, Mapping)]
    for where, who, values in entries:
        for key, value in values.items():
            if key in words:
                what, symbol, unit = words[key]
                rows.add(FRICTION, f"{who}: {what}", _symbol(symbol, where.rpartition(".")[2] if "." in where else ""),
                         number_text(value), unit, [f"friction.{where}.{key}"])


def _speed_rows(rows: _Rows, scheme: Mapping[str, Any]) -> None:
    dyn = scheme.get("dynamics")
    if not isinstance(dyn, Mapping):
        return
    base = "dynamics"
    if "mean_rpm" in dyn or "mean_speed" in dyn:
        rpm_given = "mean_rpm" in dyn
        value = float(dyn["mean_rpm"] if rpm_given else dyn["mean_speed"])
        rpm, omega = (value, value * RPM) if rpm_given else (value / RPM, value)
        rows.add(SPEED, "mean speed of the crank, signed (+ counter-clockwise)", "$n_{1}$",
                 number_text(dyn["mean_rpm"]) if rpm_given else number_text(rpm, 6), "rpm",
                 ["dynamics.mean_rpm"] if rpm_given else [])
        rows.add(SPEED, "mean angular velocity of the crank, signed: ω = 2π n / 60" if rpm_given else
                 "mean angular velocity of the crank, signed", "$\\omega_{m}$",
                 number_text(omega, 6) if rpm_given else number_text(dyn["mean_speed"]), "rad/s",
                 [] if rpm_given else ["dynamics.mean_speed"])
        rows.add(SPEED, "direction of rotation of the crank", "",
                 "counter-clockwise" if value > 0 else "clockwise")
    if "delta" in dyn:
        delta = dyn["delta"]
        inverse = 1 / delta if delta else math.inf
        extra = f" (1/{round(inverse)})" if math.isfinite(inverse) and abs(inverse - round(inverse)) < 0.02 \
            and round(inverse) > 1 else ""
        rows.add(SPEED, "coefficient of speed fluctuation δ = (ωₘₐₓ − ωₘᵢₙ) / ωₘ", "$\\delta$",
                 number_text(delta) + extra, "", ["dynamics.delta"])
    rows.add(SPEED, "table positions per turn (n; position n + 1 closes the cycle)", "$n$",
             number_text(dyn.get("positions", 12)), "", ["dynamics.positions"] if "positions" in dyn else [])
    if "start_deg" in dyn:
        rows.add(SPEED, "position 1 at the crank angle", _symbol("\\varphi", "1"), number_text(dyn["start_deg"]), "°",
                 ["dynamics.start_deg"])
    if "inertia_0" in dyn:
        rows.add(SPEED, "moment of inertia reduced to the crank besides the crank's own (rotor, gears)", "$I_{0}$",
                 number_text(dyn["inertia_0"]), "kg m^2", ["dynamics.inertia_0"])
    for k, rotor in enumerate(dyn.get("rotors", []), start=1):
        where = f"dynamics.rotors.{k - 1}"
        rows.add(SPEED, f"rotor {k}: moment of inertia about its axis", _symbol("J", f"r{k}"),
                 number_text(rotor.get("inertia")), "kg m^2", [f"{where}.inertia"])
        rows.add(SPEED, f"rotor {k}: speed ratio U = rotor speed / crank speed", _symbol("U", f"r{k}"),
                 number_text(rotor.get("ratio", 1)), "", [f"{where}.ratio"] if "ratio" in rotor else [])
    if "flywheel" in dyn:
        rows.add(SPEED, "flywheel already on the crank's shaft", "$I_{fw}$", number_text(dyn["flywheel"]), "kg m^2",
                 ["dynamics.flywheel"])
    for key, (words, unit) in {"initial_speed": ("speed at the start of the start-up", "rad/s"),
                               "initial_rpm": ("speed at the start of the start-up", "rpm"),
                               "cycles": ("turns of the start-up", "")}.items():
        if key in dyn:
            rows.add(SPEED, words, "", number_text(dyn[key]), unit, [f"{base}.{key}"])
    motor = dyn.get("motor")
    if isinstance(motor, Mapping):
        rows.add(SPEED, "motor: its characteristic", "", f"{motor.get('kind')}", "", ["dynamics.motor.kind"])
        for key, value in motor.items():
            if key != "kind":
                words, unit = _MOTOR_WORDS.get(key, (key, ""))
                rows.add(SPEED, f"motor: {words}", "", number_text(value), unit, [f"dynamics.motor.{key}"])


def data_sections(scheme: Mapping[str, Any], facts: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The sections of a sheet's data table, from a variant's scheme (the parsed ``scheme.toml``).

    Each section is ``{"title", "rows"}``; each row ``{"quantity", "symbol", "value", "unit",
    "from"}``: the quantity in words, its symbol (mathtext, or ""), its value and unit as printed,
    and the scheme entries it shows (dotted paths into the scheme: ``"links.2.length"``). A
    scheme entry no other row words gets a row of its own in the section :data:`FURTHER`, so that
    every entry is printed. ``facts`` holds what is computed from the mechanism:
    ``"phi1_deg"`` (the input angle of position 1) and ``"position_1"`` (its rule in words).
    """
    rows = _Rows()
    _link_rows(rows, scheme)
    _pair_rows(rows, scheme)
    _motion_rows(rows, scheme, facts)
    _load_rows(rows, scheme)
    _speed_rows(rows, scheme)
    _friction_rows(rows, scheme)
    shown = {src for section in rows.sections.values() for row in section for src in row["from"]}
    shown |= {src for d in load_diagrams(scheme) for row in _diagram_table_rows(d) for src in row["from"]}
    for path, value in scheme_leaves(scheme).items():
        if not any(path == s or path.startswith(s + ".") for s in shown):
            rows.add(FURTHER, path, "", number_text(value), "", [path])
    return rows.result()


# ----------------------------------------------------------------------------------------------
# the load diagrams
# ----------------------------------------------------------------------------------------------


def _zones(fractions: Sequence[float], values: Sequence[float]) -> list[dict[str, float]]:
    """The pieces of a diagram between distinct fractions: ``{"from", "to", "start", "end"}``."""
    return [{"from": fractions[i], "to": fractions[i + 1], "start": values[i], "end": values[i + 1]}
            for i in range(len(fractions) - 1) if fractions[i + 1] > fractions[i]]


def zone_text(zone: Mapping[str, float], unit: str) -> str:
    """``"0.5 – 0.95: 0 → 31250 N"``, or ``"0.05 – 0.95: 2750 N"`` for a constant piece."""
    span = f"{number_text(zone['from'])} – {number_text(zone['to'])}"
    if zone["start"] == zone["end"]:
        return f"{span}: {number_text(zone['start'])} {unit_text(unit)}"
    return f"{span}: {number_text(zone['start'])} → {number_text(zone['end'])} {unit_text(unit)}"


def _stroke(base: str, key: str, values_key: str, diagram: Mapping[str, Any], stroke: str) -> dict[str, Any]:
    fractions, values = list(diagram[key]), list(diagram[values_key])
    return {"stroke": stroke, "fractions": fractions, "values": values, "zones": _zones(fractions, values),
            "from": [f"{base}.{key}", f"{base}.{values_key}"]}


def load_diagrams(scheme: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Every load given as a diagram or a cycle table, in a student's words and numbers.

    Each: ``name`` (``"F1"``, ``"M1"``), ``title``, ``unit`` (N or N·m), ``kind`` (``"stroke"``:
    over the working (and idle) stroke of ``coordinate``; ``"cycle"``: at the table positions),
    ``working`` (``"+"``/``"-"``), ``opposes``, ``signed``, and ``strokes`` (the working stroke and,
    when declared, the idle one: the fractions, values and zones as declared) or ``positions`` and
    ``values`` of a cycle table.
    """
    loads = scheme.get("loads", {})
    found = []
    entries = [("F", k, spec, "forces") for k, spec in enumerate(loads.get("forces", []), start=1)]
    entries += [("M", k, spec, "moments") for k, spec in enumerate(loads.get("moments", []), start=1)]
    for letter, k, spec, group in entries:
        base = f"loads.{group}.{k - 1}"
        name = f"{letter}{k}"
        unit = "N" if letter == "F" else "N·m"
        directed = "between" in spec or "along_link" in spec
        point = spec.get("point")
        link = spec.get("link") or (_force_link(scheme, point) if point else "?")
        if letter == "M":
            link = spec.get("link", "?")
            where = f"moment on link {link}"
        else:
            where = f"force at {point} of link {link}"
        if isinstance(spec.get("diagram"), Mapping):
            diagram = spec["diagram"]
            along = diagram.get("along")
            coordinate = diagram.get("quantity") if directed else (f"{point}.{along}" if letter == "F" else
                                                                   f"{link}.theta")
            entry = {"name": name, "title": f"{where}: its diagram over the stroke of {coordinate}", "unit": unit,
                     "kind": "stroke", "coordinate": coordinate, "along": along,
                     "working": "+" if diagram.get("working") in ("+", 1) else "-",
                     "opposes": bool(diagram.get("opposes", True)), "signed": directed,
                     "strokes": [_stroke(f"{base}.diagram", "fractions", "values", diagram, "working")]}
            if "idle_fractions" in diagram:
                entry["strokes"].append(_stroke(f"{base}.diagram", "idle_fractions", "idle_values", diagram, "idle"))
            found.append(entry)
        elif "cycle" in spec:
            values = list(spec["cycle"])
            found.append({"name": name, "title": f"{where}: its values at the table positions", "unit": unit,
                          "kind": "cycle", "along": spec.get("along"), "signed": True,
                          "positions": list(range(1, len(values) + 1)), "values": values,
                          "from": [f"{base}.cycle"]})
    return found


def _diagram_table_rows(diagram: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The rows of a diagram's table (``section`` = the diagram's title), each naming its sources."""
    rows = []
    name, unit = subscripted(diagram["name"]), unit_text(diagram["unit"])
    if diagram["kind"] == "cycle":
        src = diagram["from"][0]
        for i, (pos, value) in enumerate(zip(diagram["positions"], diagram["values"], strict=True)):
            rows.append({"quantity": f"{name} at position {pos}", "symbol": "", "value": number_text(value),
                         "unit": unit, "from": [f"{src}.{i}"]})
        return rows
    for stroke in diagram["strokes"]:
        fk, vk = stroke["from"]
        for i, (t, value) in enumerate(zip(stroke["fractions"], stroke["values"], strict=True)):
            rows.append({"quantity": f"{name}, {stroke['stroke']} stroke, t = {number_text(t)}", "symbol": "",
                         "value": number_text(value), "unit": unit, "from": [f"{fk}.{i}", f"{vk}.{i}"]})
    return rows


# ----------------------------------------------------------------------------------------------
# given.json
# ----------------------------------------------------------------------------------------------


def _position_1(mech: Mechanism) -> dict[str, Any]:
    """Position 1 of the tables: the input angle (deg; ``s1``, m, for a slide input), its rule in
    words and the positions per turn (or over the range)."""
    n, start = table_defaults(mech)
    phi, used = table_positions(mech, n, start, declared_rotation(mech))
    if mech.input_range is not None:
        rule = "the first end of the input's range"
    elif isinstance(used, str) and mech.output is not None:
        rule = f"the output {mech.output.quantity} {_START_WORDS.get(mech.output.start, mech.output.start)}"
    elif mech.output is None and isinstance(start, str):
        rule = "φ = 0: the scheme declares no output"
    else:
        rule = "the declared start angle"
    if not mech.coordinate.is_angle:
        return {"s1": float(phi[0]), "position_1": rule, "positions": int(n)}
    angle = float(np.mod(np.degrees(phi[0]), 360.0))
    angle = 0.0 if angle >= 360.0 - 5e-10 else angle
    return {"phi1_deg": angle, "position_1": rule, "positions": int(n)}


def given_data(template: Any, variant: Any, values: Mapping[str, Any], mech: Mechanism,
               scheme_text: str) -> dict[str, Any]:
    """What the student of one variant is given, as plain JSON-serialisable data (``given.json``).

    Parameters
    ----------
    template : Template
        The variant's template (its name, description, tasks and parameters).
    variant : Variant
        The variant (its ``label`` and ``folder()``).
    values : mapping
        Every parameter's value (``template.values(variant.free)``).
    mech : Mechanism
        The variant's mechanism (``loads(scheme_text)``): position 1 is computed from it.
    scheme_text : str
        The variant's ``scheme.toml``: held whole under ``"scheme"``.

    Returns
    -------
    dict
        ``format``, ``variant``, ``folder``, ``template``, ``title``, ``description``, ``tasks``,
        ``parameters`` (name, label, value, unit), ``position_1`` (the input angle of position 1,
        deg, its rule in words, the positions per turn and the sense of rotation), ``grading``
        (``[template.grading]`` with the points asked named: :func:`grading_from_given`),
        ``data`` (the sections of the data table, :func:`data_sections`, and what is graded,
        :func:`grading_section`), ``diagrams`` (:func:`load_diagrams`) and ``scheme``.
        Deterministic: no path, no time.
    """
    scheme = tomllib.loads(scheme_text)
    facts = _position_1(mech)
    rotation = declared_rotation(mech)
    facts["rotation"] = "counter-clockwise" if rotation > 0 else "clockwise"
    parameters = [{"name": p.name, "label": p.label, "value": values[p.name], "unit": p.unit}
                  for p in template.parameters]
    grading = _grading(getattr(template, "grading", None) or Grading(), mech)
    return {
        "format": GIVEN_FORMAT,
        "variant": variant.label,
        "folder": variant.folder(),
        "template": template.name,
        "title": f"Assignment {variant.label} — {template.name}",
        "description": template.description,
        "tasks": list(template.tasks),
        "parameters": parameters,
        "position_1": facts,
        "grading": grading,
        "data": [*data_sections(scheme, facts), grading_section(grading, facts)],
        "diagrams": load_diagrams(scheme),
        "scheme": scheme,
    }


def _grading(grading: Grading, mech: Mechanism) -> dict[str, Any]:
    """``[template.grading]`` as data, its points resolved (the key's default points named)."""
    return {"tolerance": grading.tolerance, "digits": grading.digits,
            "points": list(grading.points) if grading.points is not None else list(default_points(mech)),
            "force_positions": list(grading.force_positions) if grading.force_positions is not None else None,
            "tolerances": dict(grading.tolerances)}


def grading_from_given(given: Mapping[str, Any]) -> Grading:
    """The :class:`~linkage.course.template.Grading` a variant's key was made with, from its
    ``given.json`` (``answer_key(scheme_from_given(g), grading_from_given(g))`` is its key)."""
    raw = given.get("grading") or {}
    positions = raw.get("force_positions")
    return Grading(tolerance=raw.get("tolerance", 0.02), digits=raw.get("digits", 4),
                   points=tuple(raw["points"]) if raw.get("points") is not None else None,
                   force_positions=tuple(positions) if positions is not None else None,
                   tolerances=dict(raw.get("tolerances") or {}))


def _percent(tolerance: float) -> str:
    return f"{number_text(100 * tolerance, 6)} %"


def grading_section(grading: Mapping[str, Any], facts: Mapping[str, Any]) -> dict[str, Any]:
    """The section of the data table that says what is graded and how (``given["grading"]``)."""
    rows = _Rows()
    title = GRADING
    rows.sections[title] = []
    n = facts.get("positions")
    positions = grading.get("force_positions")
    rows.add(title, "points whose position, analogs, velocity and acceleration you report", "",
             ", ".join(grading.get("points") or []) or "none")
    rows.add(title, "table positions of the kinetostatic analysis (reactions, balancing moments)", "",
             ", ".join(str(k) for k in positions) if positions is not None else
             (f"every position, 1 … {n + 1}" if n else "every position"))
    rows.add(title, "analogs: per rad of crank rotation, d/dψ (ψ: the angle turned from position 1 in the "
             "direction of rotation)", "", "x′ = dx/dψ, x″ = d²x/dψ²")
    rows.add(title, "significant digits to report", "", number_text(grading.get("digits", 4)))
    rows.add(title, "a value passes within (relative to the larger of the value and its quantity's scale)", "",
             _percent(grading.get("tolerance", 0.02)))
    for quantity, tolerance in (grading.get("tolerances") or {}).items():
        rows.add(title, f"tolerance of {quantity}", "", _percent(tolerance))
    rows.add(title, "your answers: the file answers.csv of your variant's folder", "",
             "student, variant, quantity, position, value")
    return {"title": title, "rows": rows.sections[title]}


def given_json(given: Mapping[str, Any]) -> str:
    """The text of ``given.json``: UTF-8 JSON (real symbols, not escapes), one space of indent."""
    return json.dumps(given, ensure_ascii=False, indent=1, sort_keys=False, allow_nan=False) + "\n"


def scheme_from_given(given: Mapping[str, Any]) -> Mechanism:
    """The variant's mechanism rebuilt from its ``given.json`` alone (its ``"scheme"``).

    Raises
    ------
    InputError
        ``given`` holds no scheme.
    SchemeError
        The scheme is invalid (each problem prefixed with the variant).
    """
    scheme = given.get("scheme") if isinstance(given, Mapping) else None
    if not isinstance(scheme, Mapping):
        raise InputError("given.json holds no \"scheme\" table: it was not written by linkage variants")
    try:
        return from_dict(scheme, default_name=str(scheme.get("name", given.get("folder", "variant"))))
    except SchemeError as exc:
        raise SchemeError([f"given.json of variant {given.get('variant')!r}: {p}" for p in exc.problems]) from None


def scheme_leaves(scheme: Mapping[str, Any]) -> dict[str, Any]:
    """Every datum of a scheme: dotted path -> number, string or bool (lists by index), without
    :data:`NOT_DATA`.

    >>> scheme_leaves({"name": "x", "links": {"1": {"line": ["O", "A"], "length": 0.1}}})
    {'links.1.line.0': 'O', 'links.1.line.1': 'A', 'links.1.length': 0.1}
    """
    def walk(value: Any, path: str) -> Iterator[tuple[str, Any]]:
        if isinstance(value, Mapping):
            for k, v in value.items():
                yield from walk(v, f"{path}.{k}" if path else str(k))
        elif isinstance(value, list):
            for i, v in enumerate(value):
                yield from walk(v, f"{path}.{i}")
        else:
            yield path, value

    return {p: v for k, val in scheme.items() if k not in NOT_DATA for p, v in walk(val, str(k))}


def sheet_rows(given: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Every row of data a sheet prints from ``given``: the parameters (those with a label), the
    data table's sections and the tables of the load diagrams; each row with its ``section`` and
    its ``kind`` (``"parameter"``, ``"data"`` or ``"diagram"``)."""
    rows = [{"section": PARAMETERS, "kind": "parameter", "quantity": p["label"], "symbol": "",
             "value": number_text(p["value"]), "unit": unit_text(p["unit"]), "from": []}
            for p in given.get("parameters", []) if p.get("label")]
    for section in given.get("data", []):
        rows += [{"section": section["title"], "kind": "data", **row} for row in section["rows"]]
    for diagram in given.get("diagrams", []):
        rows += [{"section": diagram["title"], "kind": "diagram", **row} for row in _diagram_table_rows(diagram)]
    return rows
