"""The builder: the one way to declare a mechanism (the scheme loader calls it too).

:class:`MechanismBuilder` takes links, pairs, inputs, their laws, assembly conditions, the output
and the input range one call at a time, collecting every problem of the declaration, and
:meth:`~MechanismBuilder.build` returns the frozen :class:`~linkage.model.mechanism.Mechanism`
or raises one :class:`~linkage.errors.SchemeError` listing them all (:func:`validate`: the
problems of the graph as a whole -- pairs, inputs, their laws, assembly conditions, the output).

>>> b = MechanismBuilder("four_bar")
>>> _ = b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)})
>>> _ = b.link("1", line=("O", "A"), length=0.1)
>>> _ = b.link("2", line=("A", "B"), length=0.3)
>>> _ = b.link("3", line=("C", "B"), length=0.25)
>>> for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
...     _ = b.revolute(name, a, c)
>>> _ = b.inputs("1").assembly("B", left_of=("A", "C"))
>>> b.build().name
'four_bar'
"""

from __future__ import annotations

import math
from typing import Any, Mapping

from ..errors import SchemeError
from .input_laws import InputLaw, table_problems
from .mechanism import Assembly, Guide, Link, Mechanism, Output, Prismatic, Revolute, law_problems
from .numbers import MAX_MAGNITUDE, Vec, angle_from, check_number, coordinates_from, is_number, unknown_keys

__all__ = ["MechanismBuilder", "validate"]


class MechanismBuilder:
    """Declare a mechanism step by step, then :meth:`build` it (validated, all problems at once).

    Every method returns the builder so calls can be chained. Lengths in m, angles in rad
    (or ``*_deg`` keys in point / guide specifications), masses in kg.
    """

    def __init__(self, name: str, description: str = "", frame: str = "0"):
        self.name = name
        self.description = description
        self.frame = frame
        self._links: dict[str, Link] = {}
        self._pairs: dict[str, Revolute | Prismatic] = {}
        self._inputs: list[str] = []
        self._laws: dict[str, InputLaw] = {}
        self._law_degrees: dict[str, tuple[str, ...]] = {}
        self._assembly: list[Assembly] = []
        self._output: Output | None = None
        self._range: tuple[float, float] | None = None
        self._range_in_degrees = False
        self._range_given: str | None = None
        self._problems: list[str] = []
        self._rejected: set[str] = set()  # links and pairs refused (reported already)
        self._unplaced: dict[str, set[str]] = {}  # link -> its points and guides refused
        self._incomplete: set[str] = set()  # links whose refused line leaves its points unknown
        self._inputs_refused = False

    # -- links ---------------------------------------------------------------------------------
    def link(
        self,
        name: str,
        *,
        line: tuple[str, str] | None = None,
        length: float | None = None,
        points: Mapping[str, Any] | None = None,
        guides: Mapping[str, Any] | None = None,
        mass: float | None = None,
        com: str | Vec | None = None,
        inertia: float | None = None,
    ) -> "MechanismBuilder":
        """Declare a link.

        Parameters
        ----------
        name : str
            Link name (the frame is ``self.frame``, "0" by default).
        line, length : (str, str), float
            A binary link by its length: ``line[0]`` at the local origin, ``line[1]`` at
            ``(length, 0)``; the local x axis runs along the line.
        points : mapping
            More points: ``(x, y)`` in the link's frame, or ``{"from": P, "distance": d,
            "angle_deg": a}`` -- at distance d from point P, at angle a CCW from the link's x axis.
        guides : mapping
            Guide lines: ``{"through": P or (x, y), "angle_deg": a, "offset": e}``: through the
            point, at angle a from the link's x axis, shifted by e along the line's left normal.
        mass, com, inertia : float, str or (x, y), float
            Mass (kg), centre of mass (a point name or local coordinates), J_S (kg m^2).
        """
        where = f"link '{name}'"
        p = self._problems
        if name in self._links:
            p.append(f"{where}: declared twice")
            return self
        local: dict[str, Vec] = {}
        unplaced = self._unplaced.setdefault(name, set())  # declared, but refused: no follow-ons
        if line is not None or length is not None:
            if not isinstance(line, (tuple, list)) or len(line) != 2 or not all(isinstance(s, str) for s in line):
                p.append(f"{where}: 'line' must name two points, got {line!r}")
                self._incomplete.add(name)  # its points are unknown: no follow-ons about them
            elif line[0] == line[1]:
                p.append(f"{where}: 'line' joins point '{line[0]}' to itself")
                unplaced.add(line[0])
            else:
                value = check_number(length, where, "length", p, "positive", "m")
                if value is None:
                    unplaced.update(line)
                else:
                    local[line[0]] = (0.0, 0.0)
                    local[line[1]] = (value, 0.0)
        # names whose absence is reported already: refused ones (or all, when the line is unknown)
        missing = _EVERY_NAME if name in self._incomplete else unplaced
        for pname, spec in (points or {}).items():
            pwhere = f"{where} point '{pname}'"
            if pname in local:
                p.append(f"{pwhere}: declared twice")
                continue
            if isinstance(spec, Mapping):
                vec = self._relative_point(spec, local, missing, pwhere)
            else:
                vec = coordinates_from(spec, pwhere, "[x, y] or {from, distance, angle_deg}", p)
            if vec is None:
                unplaced.add(pname)
            else:
                local[pname] = vec
        link_guides: dict[str, Guide] = {}
        for gname, spec in (guides or {}).items():
            gwhere = f"{where} guide '{gname}'"
            guide = self._guide(spec, local, missing, gwhere)
            if guide is None:
                unplaced.add(gname)
            else:
                link_guides[gname] = guide
        ok_mass = mass is None or check_number(mass, where, "mass", p, "nonnegative", "kg") is not None
        ok_inertia = inertia is None or check_number(inertia, where, "inertia", p, "nonnegative",
                                                     "kg m^2") is not None
        center: Vec = (0.0, 0.0)
        if isinstance(com, str):
            if com in local:
                center = local[com]
            elif com not in missing:
                p.append(f"{where}: centre of mass must be a point of the link or [x, y], got {com!r}")
        elif com is not None:
            center = coordinates_from(com, where + " centre of mass", "a point of the link or [x, y]", p) or center
        elif ok_mass and mass:
            p.append(f"{where}: mass {mass} kg is given without a centre of mass ('com')")
        self._links[name] = Link(
            name,
            local,
            link_guides,
            float(mass) if mass is not None and ok_mass else 0.0,
            center,
            float(inertia) if inertia is not None and ok_inertia else 0.0,
            mass is not None,
        )
        return self

    def _relative_point(self, spec: Mapping[str, Any], local: dict[str, Vec], unplaced, where: str) -> Vec | None:
        p = self._problems
        unknown_keys(spec, {"from", "distance", "angle", "angle_deg"}, where, p)
        origin = spec.get("from")
        if not isinstance(origin, str) or origin not in local:
            if not (isinstance(origin, str) and origin in unplaced):  # else: reported already
                p.append(f"{where}: 'from' must name an earlier point of the link, got {origin!r}")
            return None
        distance = check_number(spec.get("distance"), where, "distance", p, "nonnegative", "m")
        angle = angle_from(spec, "angle", where, p)
        if distance is None:
            return None
        ox, oy = local[origin]
        return (ox + distance * math.cos(angle), oy + distance * math.sin(angle))

    def _guide(self, spec: Any, local: dict[str, Vec], unplaced, where: str) -> Guide | None:
        p = self._problems
        if not isinstance(spec, Mapping):
            p.append(f"{where}: expected {{through, angle_deg, offset}}, got {spec!r}")
            return None
        unknown_keys(spec, {"through", "angle", "angle_deg", "offset"}, where, p)
        through = spec.get("through", (0.0, 0.0))
        if isinstance(through, str):
            base = local.get(through)
            if base is None and through not in unplaced:
                p.append(f"{where}: 'through' must be a point of the link or [x, y], got {through!r}")
        else:
            base = coordinates_from(through, where, "'through' = a point of the link or [x, y]", p)
        angle = angle_from(spec, "angle", where, p)
        offset = check_number(spec.get("offset", 0.0), where, "offset", p, "real", "m")
        if base is None or offset is None:
            return None
        nx_, ny_ = -math.sin(angle), math.cos(angle)
        return Guide((base[0] + offset * nx_, base[1] + offset * ny_), angle)

    # -- pairs ---------------------------------------------------------------------------------
    def revolute(self, name: str, link_a: str, link_b: str, at: str | None = None) -> "MechanismBuilder":
        """Pin ``link_a`` and ``link_b`` at the point ``at`` (default: the pair's name)."""
        if self._check_pair_name(name):
            self._pairs[name] = Revolute(name, (link_a, link_b), at if at is not None else name)
        return self

    def prismatic(
        self, name: str, guide_link: str, slider_link: str, *, guide: str, at: str, angle: float = 0.0
    ) -> "MechanismBuilder":
        """Let ``slider_link``'s point ``at`` slide on guide ``guide`` of ``guide_link``.

        ``angle`` is the fixed angle of the slider's x axis to the guide direction (rad).
        """
        value = check_number(angle, f"pair '{name}'", "angle", self._problems, "angle", "rad")
        if value is None:
            self._rejected.add(name)
        elif self._check_pair_name(name):
            self._pairs[name] = Prismatic(name, (guide_link, slider_link), guide, at, value)
        return self

    def reject(self, name: str | None = None, names=(), *, inputs: bool = False) -> "MechanismBuilder":
        """Note that a declaration was refused by the caller, who has reported why (a misspelt key
        in a scheme file, say): the link or pair ``name`` (with the points and guides ``names`` it
        declares), or, with ``inputs``, the input links.

        :meth:`build` then leaves out the problems that only follow from its absence (pairs that
        join it, its points, the input's frame pair, "no input link"): one message per root cause.
        """
        if name is not None:
            self._rejected.add(name)
            self._unplaced.setdefault(name, set()).update(n for n in names if isinstance(n, str))
        self._inputs_refused = self._inputs_refused or inputs
        return self

    def _check_pair_name(self, name: str) -> bool:
        if name in self._pairs:
            self._problems.append(f"pair '{name}': declared twice")
            return False
        return True

    # -- the rest ------------------------------------------------------------------------------
    def inputs(self, *links: str) -> "MechanismBuilder":
        """Declare the input links (cranks), each pinned to the frame. The first one's angle is
        ``phi``; each further one turns by its :meth:`input_law`."""
        self._inputs.extend(links)
        return self

    def input_law(self, link: str, *, ratio: float | None = None, phase: float | None = None,
                  table=None, degrees=()) -> "MechanismBuilder":
        """The angle of the further input ``link`` as a function of the first input's ``phi``:
        ``ratio * phi + phase`` (rad; defaults 1 and 0), or ``table=(phi, theta)``, two sequences of
        angles (rad) interpolated by a cubic spline (see :class:`~linkage.model.input_laws.InputLaw`).
        For a further input that is a slide, its slide (m) ``ratio * phi + phase`` (phase in m; no
        table). ``degrees``: the scheme keys given in degrees (``phase_deg``, ``table_deg``), which
        a slide refuses."""
        if degrees:
            self._law_degrees[link] = tuple(degrees)
        where = f"input law of link '{link}'"
        if link in self._laws:
            self._problems.append(f"{where}: declared twice")
            return self
        if table is not None:
            found = table_problems(where, table) + ([f"{where}: give either a table or a ratio and a phase, not both"]
                                                    if ratio is not None or phase is not None else [])
            self._problems.extend(found)
            if not found:
                self._laws[link] = InputLaw(table=tuple(tuple(float(v) for v in column) for column in table))
            return self
        found: list[str] = []
        ratio = 1.0 if ratio is None else check_number(ratio, where, "ratio", found, "nonzero")
        phase = 0.0 if phase is None else check_number(phase, where, "phase", found, "angle", "rad")
        self._problems.extend(found)
        if not found:
            self._laws[link] = InputLaw(ratio, phase)
        return self

    def assembly(
        self,
        point: str,
        *,
        left_of: tuple[str, str] | None = None,
        right_of: tuple[str, str] | None = None,
        towards: float | None = None,
        origin: str | None = None,
        branch: int | None = None,
        mode: str = "keep",
        phi: float | None = None,
    ) -> "MechanismBuilder":
        """Pick the assembly branch of the group that places ``point``.

        Exactly one of: ``left_of=(X, Y)`` / ``right_of=(X, Y)`` (the point lies left / right of
        the directed line X -> Y); ``towards=angle`` with ``origin=X`` (the point lies from X in
        that direction, rad); ``branch=+1/-1`` (the solver's raw sign, see its kind).
        ``mode``: ``"keep"`` (default) keeps that branch through change points, ``"follow"``
        follows the motion continuously through them (see :class:`Assembly`). ``phi`` (rad):
        the input angle at which the condition holds (default: at most angles of a turn).
        """
        where = f"assembly of point '{point}'"
        if mode not in ("keep", "follow"):
            self._problems.append(f"{where}: mode must be 'keep' or 'follow', got {mode!r}")
            return self
        if phi is not None and not (is_number(phi) and math.isfinite(phi)):
            self._problems.append(f"{where}: the input angle of the condition must be a finite number, "
                                  f"got {phi!r}")
            return self
        extra = {"mode": mode, "phi": None if phi is None else float(phi)}
        given = [k for k, v in (("left_of", left_of), ("right_of", right_of), ("towards", towards),
                                ("branch", branch)) if v is not None]
        if len(given) != 1:
            self._problems.append(
                f"{where}: give exactly one of left_of, right_of, towards(_deg), branch; got {given}")
            return self
        if left_of is not None or right_of is not None:
            refs = left_of if left_of is not None else right_of
            if not (isinstance(refs, (list, tuple)) and len(refs) == 2):
                self._problems.append(f"{where}: {given[0]} must name two points, got {refs!r}")
                return self
            self._assembly.append(Assembly(point, given[0], tuple(refs), **extra))
        elif towards is not None:
            if origin is None or not is_number(towards):
                self._problems.append(f"{where}: 'towards' needs an angle and 'from' a point")
                return self
            self._assembly.append(Assembly(point, "towards", (origin,), float(towards), **extra))
        else:
            if branch not in (1, -1):
                self._problems.append(f"{where}: branch must be +1 or -1, got {branch!r}")
                return self
            self._assembly.append(Assembly(point, "branch", value=int(branch), **extra))
        return self

    def output(self, quantity: str, start: str = "max") -> "MechanismBuilder":
        """Declare the output coordinate (``"B.x"``, ``"3.theta"``, ``"K.s"``) and its start."""
        self._output = Output(quantity, start)
        return self

    def input_range(self, start: float, end: float, *, degrees: bool = False,
                    given: str | None = None) -> "MechanismBuilder":
        """Analyse the mechanism over the first input's coordinate from ``start`` to ``end``
        instead of a full turn: angles (rad) for an input that does not turn fully (a rocker
        input, a tangent mechanism; a span of more than 0 and less than a turn), or the stroke (m)
        of a slide input (which needs one).

        Tables run from ``start`` to ``end`` (``end < start`` for an input that turns clockwise or
        slides backwards). ``degrees``: the range was given in degrees (converted to rad), which
        only an input angle accepts; ``given``: how it was written (named in messages).
        """
        ok = [check_number(v, "input range", name, self._problems, "real") for v, name in
              ((start, "start"), (end, "end"))]
        if None not in ok:
            self._range = (ok[0], ok[1])
            self._range_in_degrees = degrees
            self._range_given = given
        return self

    def build(self, **extra: Any) -> Mechanism:
        """Validate and return the mechanism; raise :class:`SchemeError` listing every problem."""
        if self.frame not in self._links:
            self._links[self.frame] = Link(self.frame)
        mech = Mechanism(
            self.name,
            dict(self._links),
            dict(self._pairs),
            tuple(self._inputs),
            self.frame,
            tuple(sorted(self._assembly, key=lambda a: a.point)),
            self._output,
            self.description,
            dict(extra),
            self._range,
            dict(self._laws),
        )
        refused = dict(self._unplaced)
        for name in self._incomplete:
            refused[name] = _EVERY_NAME
        problems = self._problems + validate(mech, self._rejected, refused, inputs_refused=self._inputs_refused)
        if self._range_in_degrees and mech.inputs and not mech.coordinate.is_angle:
            problems.append(f"range_deg: input '{mech.inputs[0]}' is a slide, whose stroke is in m: give "
                            "range = [s_start, s_end] (m) instead")
        elif not self._inputs_refused:
            problems.extend(_range_problems(mech, self._range_given or "input range"))
        for link, keys in self._law_degrees.items():
            if link in mech.inputs and mech.input_kind(link) == "slide":
                problems.append(f"input_laws.{link}: {', '.join(keys)}: input '{link}' is a slide, whose coordinate "
                                "is in m: give ratio and phase (m)")
        if problems:
            raise SchemeError(problems)
        return mech


class _EveryName:
    """The points of a link whose declaration left them unknown: contains every name."""

    def __contains__(self, name) -> bool:
        return True

    def __iter__(self):
        return iter(())


_EVERY_NAME = _EveryName()


def validate(mech: Mechanism, rejected=frozenset(), unplaced: Mapping[str, set] | None = None, *,
             inputs_refused: bool = False) -> list[str]:
    """Every problem of a mechanism's declaration (empty when it is sound).

    Parameters
    ----------
    mech : Mechanism
    rejected : set of str
        Links and pairs whose declarations were refused (already reported): problems that only
        follow from their absence are left out.
    unplaced : dict of link -> set of str
        Points and guides of a link whose declarations were refused (already reported).
    inputs_refused : bool
        The declaration of the input links was refused (already reported).
    """
    p: list[str] = []
    links = mech.links
    unplaced = unplaced or {}

    def refused(link: str, name: str) -> bool:
        return link in rejected or name in unplaced.get(link, ())

    for pair in mech.pairs.values():
        where = f"pair '{pair.name}'"
        a, b = pair.links
        bad = [x for x in (a, b) if x not in links]
        for x in bad:
            if x not in rejected:
                p.append(f"{where}: joins unknown link '{x}'")
        if bad:
            continue
        if a == b:
            p.append(f"{where}: joins link '{a}' to itself")
            continue
        if isinstance(pair, Revolute):
            for x in (a, b):
                if pair.point not in links[x].points and not refused(x, pair.point):
                    p.append(f"{where}: point '{pair.point}' is not declared on link '{x}'")
        elif (pair.guide not in links[a].guides and pair.point not in links[b].points
              and pair.guide in links[b].guides and pair.point in links[a].points):
            p.append(f"{where}: links {list(pair.links)} are in the wrong order: a prismatic pair's links "
                     f"are [guide link, slider link], and guide '{pair.guide}' is on link '{b}'")
        else:
            if pair.guide not in links[a].guides and not refused(a, pair.guide):
                p.append(f"{where}: link '{a}' has no guide '{pair.guide}' "
                         f"(it has {sorted(links[a].guides) or 'none'})")
            if pair.point not in links[b].points and not refused(b, pair.point):
                p.append(f"{where}: point '{pair.point}' is not declared on slider link '{b}'")
    clash = sorted(set(mech.pairs) & set(links))
    for name in clash:
        p.append(f"name '{name}' is used for both a link and a pair")
    if not mech.inputs and not inputs_refused:
        p.append("no input link declared (input = \"<link>\")")
    if len(set(mech.inputs)) != len(mech.inputs):
        p.append(f"input links declared twice: {list(mech.inputs)}")
    for name in mech.inputs:
        p.extend(_input_problems(mech, name, rejected))
    p.extend(law_problems(mech))
    known_points = {q for lk in links.values() for q in lk.points}
    refused_points = {q for names in unplaced.values() for q in names}
    for rule in mech.assembly:
        for q in (rule.point, *rule.refs):
            if not isinstance(q, str) or (q not in known_points and q not in refused_points):
                p.append(f"assembly of point '{rule.point}': unknown point '{q}'")
    if mech.output is not None:
        p.extend(_output_problems(mech, refused=set(rejected) | refused_points))
    return p


def _input_problems(mech: Mechanism, name: str, rejected=frozenset()) -> list[str]:
    """Problems of one declared input: a link pinned to the frame or in a prismatic pair with it,
    or a pair (a revolute pair with the frame, or any prismatic pair)."""
    if name in mech.pairs:
        pair = mech.pairs[name]
        if isinstance(pair, Revolute) and mech.frame not in pair.links:
            return [f"input pair '{name}' is a revolute pair between two moving links {list(pair.links)}: an input "
                    "pair is a revolute pair with the frame (a crank) or a prismatic pair (a slide)"]
        return []
    if name not in mech.links:
        return [] if name in rejected else [f"input link '{name}' is not a declared link (nor a pair)"]
    if name == mech.frame:
        return [f"input link '{name}' is the frame"]
    if not rejected and mech.input_pair(name) is None:
        return [f"input link '{name}' is not pinned to the frame '{mech.frame}' by a revolute pair nor slides on it "
                "by a prismatic pair"]
    return []


def _range_problems(mech: Mechanism, given: str = "input range") -> list[str]:
    """Problems of the input range for the first input's coordinate: an angle's range spans more
    than 0 and less than a turn; a slide needs a stroke of nonzero length."""
    if not mech.inputs:
        return []
    span = mech.input_range
    first = mech.inputs[0]
    if mech.coordinate.is_angle:
        if span is not None and not 0 < abs(span[1] - span[0]) < 2 * math.pi:
            a, b = (math.degrees(v) for v in span)
            return [f"{given}: the range [{a:.10g}, {b:.10g}] deg must span more than 0 and less than 360 deg "
                    f"(a full turn needs no range; choose position 1 with start_deg), got a span of "
                    f"{abs(b - a):.10g} deg"]
        return []
    if span is None:
        return [f"input '{first}' is a slide (prismatic pair '{mech.input_pair(first)}'): declare its stroke, "
                "range = [s_start, s_end] in m (the slide of the pair, as in the table's column "
                f"'{mech.input_pair(first)}.s')"]
    if not span[1] != span[0] or not all(abs(v) <= MAX_MAGNITUDE for v in span):
        return [f"{given}: the stroke [{span[0]:.10g}, {span[1]:.10g}] m of slide input '{first}' must have a "
                f"nonzero length and ends within {MAX_MAGNITUDE:g} m"]
    return []


def _output_problems(mech: Mechanism, refused=frozenset()) -> list[str]:
    """Problems of the declared output; a quantity that names a ``refused`` point, link or pair is
    not reported (its declaration's problem is)."""
    out = mech.output
    where = f"output '{out.quantity}'"
    problems = []
    if out.start not in ("max", "min"):
        problems.append(f"{where}: start must be 'max' or 'min', got {out.start!r}")
    name, _, coord = out.quantity.rpartition(".")
    points = {q for lk in mech.links.values() for q in lk.points}
    ok = (
        (coord in ("x", "y") and name in points)
        or (coord == "theta" and name in mech.links and name != mech.frame)
        or (coord == "s" and isinstance(mech.pairs.get(name), Prismatic))
    )
    if not ok and name not in refused:
        problems.append(f"{where}: expected 'P.x', 'P.y' (point), 'L.theta' (moving link) or "
                        f"'K.s' (prismatic pair)")
    return problems
