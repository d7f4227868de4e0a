"""Words for people: what a table column is, what role a link plays, where a drawn position is.

- :func:`describe_column` -- a column of a table in words, with its symbol in mathtext and its
  unit for people (:class:`ColumnWords`: ready-made axis labels and legend entries), following
  docs/conventions.md ("What the columns mean"); with the mechanism it names the role of the link
  or point (crank, rocker, slider ...);
- :func:`link_role`, :func:`input_word` -- the role of a link, the name of the input;
- :func:`unit_for_people` (``"N m"`` -> ``"N·m"``), :func:`subscript` (a name as a mathtext
  subscript);
- :func:`position_caption` -- the caption above a drawing of one position: its number, the input
  angle (or slide) in words, what the dashed lines are; :func:`trajectory_note`.

They need no matplotlib.

>>> import linkage
>>> describe_column("3.theta", linkage.load("four_bar")).words
'angle of rocker 3'
>>> link_role(linkage.load("slider_crank"), "3")
'slider'
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..kinematics.motion import table_positions_deg
from ..model.mechanism import Mechanism, Prismatic
from .tables import column_unit

__all__ = ["ColumnWords", "describe_column", "link_role", "input_word", "unit_for_people", "subscript",
           "position_caption", "position_head", "speed_words", "table_span", "plain", "trajectory_note", "CAPTION_CHARS",
           "COMPACT_CHARS"]


@dataclass(frozen=True)
class ColumnWords:
    """A table column in words.

    Attributes
    ----------
    name : str
        The column name (``"B.x'"``).
    words : str
        What it is (``"velocity analog of B along x"``).
    symbol : str
        Its symbol in matplotlib mathtext (``"$x'_{B}$"``), or ``""``.
    unit : str or None
        Its unit for people (``"m/rad"``, ``"N·m"``, ``"kg·m²"``), None for a pure number.
    kind : str
        The family it belongs to, plural (``"velocity analogs"``): the axis label of a panel that
        holds several columns.
    note : str
        A convention the legend adds after the unit (``"CCW positive"``; for an analog what it is
        per, ``"per rad of crank rotation"``), or ``""``.
    derivative : str
        An analog written as the derivative it is, in mathtext (``"$dx_{B}/d\\psi$"``: with
        respect to psi, the input angle turned from position 1 in the direction of rotation, the
        diagrams' x axis; ``/ds`` for a slide input), or ``""`` for any other column.
    """

    name: str
    words: str
    symbol: str
    unit: str | None
    kind: str
    note: str = ""
    derivative: str = ""

    @property
    def defined(self) -> str:
        """The symbol, with the derivative it stands for when it is an analog
        (``"$x'_{B} = dx_{B}/d\\psi$"``)."""
        if self.derivative and self.symbol:
            return f"{self.symbol[:-1]} = {self.derivative[1:]}"
        return self.symbol or self.derivative

    @property
    def short(self) -> str:
        """The symbol of an axis label: the derivative of an analog, else the symbol."""
        return self.derivative or self.symbol

    @property
    def axis(self) -> str:
        """Axis label: words, symbol (an analog's derivative) and unit (``"slider position $x_{B}$, m"``,
        ``"slider velocity analog $dx_{B}/d\\psi$, m/rad"``)."""
        text = f"{self.words} {self.short}".strip()
        return f"{text}, {self.unit}" if self.unit else text

    @property
    def legend(self) -> str:
        """Legend entry: words, symbol and unit (``"velocity analog of B along x $x'_{B} = dx_{B}/d\\psi$
        (m/rad, per rad of crank rotation)"``)."""
        text = f"{self.words} {self.defined}".strip()
        extra = ", ".join(x for x in (self.unit, self.note) if x)
        return f"{text} ({extra})" if extra else text


def unit_for_people(unit: str | None) -> str | None:
    """``"N m"`` -> ``"N·m"``, ``"m/rad^2"`` -> ``"m/rad²"`` (None stays None)."""
    if not unit:
        return None
    return unit.replace("^2", "²").replace("^3", "³").replace(" ", "·")


def subscript(name: str) -> str:
    """A name as a mathtext subscript: upright, special characters escaped."""
    escaped = re.sub(r"([_$%#&{}^~\\])", r"\\\1", name)
    return "{\\mathrm{" + escaped + "}}"


def input_word(mech: Mechanism | None) -> str:
    """``"crank"`` (the input turns fully; also when unknown), ``"input link"`` (an angle over a
    range), ``"input slider"`` (a link driven along a frame guide) or ``"cylinder"`` (a driven
    prismatic pair between two moving links)."""
    if mech is None or not mech.inputs:
        return "crank"
    if not mech.coordinate.is_angle:
        return "cylinder" if mech.inputs[0] in mech.pairs else "input slider"
    return "input link" if mech.input_range is not None else "crank"


def link_role(mech: Mechanism, link: str) -> str:
    """The role of a link in words: ``crank`` (``input link`` over an input range), ``slider`` (on
    a guide of the frame), ``rocker`` (pivoted on the frame), ``block`` (a one-point link sliding
    in a moving guide), ``coupler`` (any other), ``frame``."""
    if link == mech.frame:
        return "frame"
    if link in mech.inputs:
        return input_word(mech)
    pairs = [p for p in mech.pairs.values() if link in p.links]
    if any(isinstance(p, Prismatic) and p.links == (mech.frame, link) for p in pairs):
        return "slider"
    if any(not isinstance(p, Prismatic) and mech.frame in p.links for p in pairs):
        return "rocker"
    if len(mech.links[link].points) == 1 and any(isinstance(p, Prismatic) and p.links[1] == link for p in pairs):
        return "block"
    return "coupler"


def _slider_axis(mech: Mechanism, point: str, axis: int) -> bool:
    """Whether ``point`` is a slider's point on a frame guide along the global ``axis`` (0 x, 1 y)."""
    for pair in mech.pairs.values():
        if isinstance(pair, Prismatic) and pair.links[0] == mech.frame and pair.point == point:
            guide = mech.links[mech.frame].guides.get(pair.guide)
            if guide is not None and abs((math.cos, math.sin)[axis](guide.angle)) > 0.999:
                return True
    return False


_PRIMES = ("", "'", "''")
_ORDER_WORDS = ("", "velocity analog", "acceleration analog")


#: whole-name columns: words, symbol, family ({crank} is the input link's role)
_NAMED = {
    "i": ("position number", "$i$", "position numbers"),
    "phi_deg": ("{crank} angle turned from position 1", r"$\psi$", "angles"),
    "s": ("slide of the {crank}", "$s$", "slides"),
    "balancing_force": ("balancing force on the {crank}", "$F_b$", "forces"),
    "v": ("speed of the {crank}", "$v$", "speeds"),
    "a": ("acceleration of the {crank}", "$a$", "accelerations"),
    "force": ("force of the actuator", "$F$", "forces"),
    "reduced_force": ("reduced force", "$F_{red}$", "forces"),
    "reduced_mass": ("reduced mass", "$m_{red}$", "masses"),
    "t": ("time", "$t$", "times"),
    "omega": ("angular velocity of the {crank}", r"$\omega$", "angular velocities"),
    "eps": ("angular acceleration of the {crank}", r"$\varepsilon$", "angular accelerations"),
    "balancing_moment": ("balancing moment on the {crank}", "$M_b$", "moments"),
    "reduced_moment_resistance": ("reduced moment of the resistance and gravity", "$M_c$", "moments"),
    "reduced_moment_driving": ("reduced moment of the driving loads", "", "moments"),
    "reduced_inertia": ("reduced moment of inertia", "$I$", "moments of inertia"),
    "reduced_inertia_derivative": ("derivative of the reduced moment of inertia", r"$dI/d\psi$",
                                   "derivatives of the moment of inertia"),
}


#: sign conventions the legends repeat (docs/conventions.md)
_NOTES = {"balancing_moment": "CCW positive", "balancing_force": "positive along +s",
          "reduced_moment_resistance": "positive when driving",
          "reduced_moment_driving": "positive when driving"}


def describe_column(name: str, mechanism: Mechanism | None = None) -> ColumnWords:
    """A table column in words, with its symbol and unit (from :func:`~linkage.report.tables.column_unit`).

    The words follow from the column name (docs/conventions.md, "What the columns mean"); with the
    mechanism they also name the role of the link or point (crank, rocker, slider ...).

    Parameters
    ----------
    name : str
        A column name: ``"B.x"``, ``"B.x'"``, ``"3.theta''"``, ``"slide.s"``, ``"A.R"``,
        ``"balancing_moment"``, ``"phi_deg"`` ...
    mechanism : Mechanism, optional
        The mechanism the column belongs to.

    Returns
    -------
    ColumnWords
        ``.axis`` and ``.legend`` are ready-made labels.

    Examples
    --------
    >>> import linkage
    >>> mech = linkage.load("slider_crank")
    >>> describe_column("B.x", mech).axis
    'slider position $x_{\\\\mathrm{B}}$, m'
    >>> describe_column("B.x'").legend
    "velocity analog of B along x $x'_{\\\\mathrm{B}} = dx_{\\\\mathrm{B}}/d\\\\psi$ (m/rad, per rad of crank rotation)"
    >>> describe_column("phi_deg", mech).axis
    'crank angle turned from position 1 $\\\\psi$, deg'
    >>> describe_column("3.theta", linkage.load("four_bar")).words
    'angle of rocker 3'
    """
    per = mechanism.coordinate.unit if mechanism is not None and mechanism.inputs else "rad"
    unit = unit_for_people(column_unit(name, per))
    crank = input_word(mechanism)
    several = mechanism is not None and len(mechanism.inputs) > 1
    if name in _NAMED:
        words, symbol, kind = _NAMED[name]
        note = _NOTES.get(name, "")
        if several and name == "balancing_moment":      # several inputs: name the first
            first = mechanism.inputs[0]
            words, symbol = f"balancing moment on {crank} {first}", f"$M_{{b,{subscript(first)}}}$"
        return ColumnWords(name, words.format(crank=crank), symbol, unit, kind, note)
    obj, dot, quantity = name.rpartition(".")
    if obj == "balancing_moment":                       # a further input link's
        role = link_role(mechanism, quantity) if mechanism is not None and quantity in mechanism.links else "link"
        return ColumnWords(name, f"balancing moment on {role} {quantity}", f"$M_{{b,{subscript(quantity)}}}$", unit,
                           "moments", _NOTES["balancing_moment"])
    base = quantity.rstrip("'")
    order = len(quantity) - len(base)
    if not dot or order > 2:
        return ColumnWords(name, name, "", unit, name)
    sub, prime = subscript(obj), _PRIMES[order]
    per_input = _per_input(mechanism, order, ("\\theta" if base == "theta" else base) + "_" + sub)
    if base in ("x", "y"):
        axis = "xy".index(base)
        symbol = f"${base}{prime}_{sub}$"
        if mechanism is not None and _slider_axis(mechanism, obj, axis):
            words = ("slider position", "slider velocity analog", "slider acceleration analog")[order]
        else:
            words = f"{base} coordinate of {obj}" if order == 0 else f"{_ORDER_WORDS[order]} of {obj} along {base}"
        kind = ("coordinates", "velocity analogs", "acceleration analogs")[order]
        return ColumnWords(name, words, symbol, unit, kind, *per_input)
    if base == "theta":
        role = link_role(mechanism, obj) if mechanism is not None and obj in mechanism.links else "link"
        what = ("angle", "angular velocity analog", "angular acceleration analog")[order]
        kind = ("link angles", "angular velocity analogs", "angular acceleration analogs")[order]
        return ColumnWords(name, f"{what} of {role} {obj}", f"$\\theta{prime}_{sub}$", unit, kind, *per_input)
    if base == "s":
        words = "slide in pair " + obj if order == 0 else f"{_ORDER_WORDS[order]} of the slide in pair {obj}"
        kind = ("slides", "velocity analogs", "acceleration analogs")[order]
        return ColumnWords(name, words, f"$s{prime}_{sub}$", unit, kind, *per_input)
    if order == 0 and base in ("R", "Rx", "Ry"):
        words = {"R": f"reaction in pair {obj}", "Rx": f"x component of the reaction in pair {obj}",
                 "Ry": f"y component of the reaction in pair {obj}"}[base]
        symbol = {"R": f"$R_{sub}$", "Rx": f"$R_{{{sub},x}}$", "Ry": f"$R_{{{sub},y}}$"}[base]
        return ColumnWords(name, words, symbol, unit, "reactions")
    if order == 0 and base == "angle_deg":
        return ColumnWords(name, f"direction of the reaction in pair {obj}", f"$\\alpha_{sub}$", unit,
                           "directions of reactions")
    if order == 0 and base == "M":
        return ColumnWords(name, f"moment in pair {obj}", f"$M_{sub}$", unit, "moments", "CCW positive")
    return ColumnWords(name, name, "", unit, name)


def _per_input(mechanism: Mechanism | None, order: int, quantity: str) -> tuple[str, str]:
    """What an analog of order 1 or 2 is per, in words, and the analog as a derivative in
    mathtext: with respect to psi, the angle turned from position 1 in the direction of rotation
    (``"per rad of crank rotation"``, ``"$dx_{B}/d\\psi$"``), or to the slide s of a slide input
    (``"per m of cylinder travel"``, ``"$dx_{B}/ds$"``); ``("", "")`` for order 0."""
    if not order:
        return "", ""
    crank = input_word(mechanism)
    slide = mechanism is not None and bool(mechanism.inputs) and not mechanism.coordinate.is_angle
    unit, what, var = ("m", "travel", "s") if slide else ("rad", "rotation", "\\psi")
    power = "²" if order == 2 else ""
    note = f"per {unit}{power} of {crank} {what}"
    if order == 1:
        return note, f"$d{quantity}/d{var}$"
    return note, f"$d^2{quantity}/d{var}^2$"


# ----------------------------------------------------------------------------------------------
# the position of a drawing in words
# ----------------------------------------------------------------------------------------------


def plain(value: float, spec: str) -> str:
    """``format(value, spec)`` without a minus on a value that rounds to zero ("0.0", never
    "-0.0").

    >>> plain(-0.01, ".1f"), plain(-0.0, ".4g"), plain(-2.5, ".1f")
    ('0.0', '0', '-2.5')
    """
    text = format(value, spec)
    return text[1:] if text.startswith("-") and not any(c in "123456789" for c in text.split("e")[0]) else text


def _closed_turn(motion) -> bool:
    """Whether the table's last row is its first a turn later (a crank's table over 360°)."""
    phi = np.asarray(motion.phi, dtype=float)
    return (motion.mechanism.coordinate.is_angle and len(phi) > 2
            and abs(abs(phi[-1] - phi[0]) - 2 * np.pi) < 1e-9)


def speed_words(motion) -> str:
    """At what speed a kinetostatic analysis was made: "no speed given: static reactions, without
    inertia forces", "at ω = 10 rad/s" or "at ω from 9.5 to 10.5 rad/s" (of the input)."""
    omega = motion.omega
    if omega is None or not np.any(np.isfinite(omega) & (omega != 0)):
        return "no speed given: static reactions, without inertia forces"
    finite = omega[np.isfinite(omega)]
    unit = "rad/s" if motion.mechanism.coordinate.is_angle else "m/s"
    what = "ω" if motion.mechanism.coordinate.is_angle else "v"
    if np.ptp(finite) <= 1e-12 * np.max(np.abs(finite)):
        return f"at {what} = {plain(float(finite[0]), '.5g')} {unit}".replace("-", "−")
    return (f"at {what} from {plain(float(finite.min()), '.4g')} to {plain(float(finite.max()), '.4g')} "
            f"{unit}").replace("-", "−")


def position_head(motion, i: int) -> str:
    """"Position i of n": n the distinct positions of the table (12 for a table of 13 rows over a
    turn, whose row 13 is position 1 a turn later).

    >>> import linkage
    >>> mech = linkage.load("four_bar")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> position_head(motion, 0), position_head(motion, 3), position_head(motion, 12)
    ('Position 1 of 12', 'Position 4 of 12', 'Position 1 of 12, a turn later')
    """
    n = len(motion.phi)
    if n == 1:
        return f"Position {i + 1}"
    if _closed_turn(motion):
        return f"Position 1 of {n - 1}, a turn later" if i == n - 1 else f"Position {i + 1} of {n - 1}"
    return f"Position {i + 1} of {n}"


def table_span(motion) -> str:
    """The table positions in words: "12 positions over a turn (13 = 1)" or "13 positions over
    0.7 m of the input's slide" / "over 40.11° of the input's turn".

    >>> import linkage
    >>> mech = linkage.load("cylinder_boom")
    >>> table_span(linkage.analyze(mech, linkage.table_angles(mech, 12)))
    "13 table positions over 0.7 m of the cylinder's slide"
    """
    n = len(motion.phi)
    if n == 1:
        return "1 table position"
    if _closed_turn(motion):
        return f"{n - 1} table positions over a turn ({n} = 1)"
    mech = motion.mechanism
    if mech.coordinate.is_angle:
        span = abs(float(table_positions_deg(motion.phi, motion.direction)[-1]))
        return f"{n} table positions over {plain(span, '.4g')}° of the {input_word(mech)}'s turn"
    span = abs(float(motion.phi[-1] - motion.phi[0]))
    return f"{n} table positions over {plain(span, '.4g')} m of the {input_word(mech)}'s slide"


def position_caption(motion, i: int, trajectories: Sequence[str] = (), compact: bool = False) -> str:
    """The position number and the input angle in words (and what the dashed lines are), in lines
    that fit above a drawing: :data:`CAPTION_CHARS` (:data:`COMPACT_CHARS` for a panel of a grid)."""

    mech = motion.mechanism
    if not mech.coordinate.is_angle:
        return _wrapped_caption(mech, _slide_phrases(motion, i, compact), trajectories, compact)
    direction = motion.direction
    turned = float(table_positions_deg(motion.phi, direction)[i])
    sense = "counter-clockwise" if direction > 0 else "clockwise"
    absolute = float(np.mod(np.degrees(motion.phi[i]), 360.0))
    if absolute >= 359.95:
        absolute = 0.0
    who = "input link" if mech.input_range is not None else "crank"
    head = position_head(motion, i)
    at = f"φ = {plain(absolute, '.1f')}°" if compact else f"φ = {plain(absolute, '.1f')}° from the x axis"
    if i == 0 or len(motion.phi) == 1 or plain(turned, ".4g") == "0":
        phrases = [f"{head}:", f"the {who} at {at}"]
    else:
        phrases = [f"{head}:", f"the {who} turned {plain(turned, '.4g')}°", sense, "from position 1", f"({at})"]
    return _wrapped_caption(mech, phrases, trajectories, compact)


def _slide_phrases(motion, i: int, compact: bool) -> list[str]:
    """The phrases of a caption for a slide input: how far it moved from position 1, and where."""
    mech = motion.mechanism
    who = input_word(mech)
    s0, s = float(motion.phi[0]), float(motion.phi[i])
    head = position_head(motion, i)
    at = f"s = {plain(s, '.4g')} m"
    moved = s - s0
    if i == 0 or len(motion.phi) == 1 or plain(moved, ".4g") == "0":
        return [f"{head}:", f"the {who} at {at}"]
    if who == "cylinder":
        verb = "extended" if moved >= 0 else "retracted"
        return [f"{head}:", f"the {who} {verb} by {plain(abs(moved), '.4g')} m", "from position 1", f"({at})"]
    return [f"{head}:", f"the {who} moved {plain(abs(moved), '.4g')} m", "towards +s" if moved >= 0 else "towards −s",
            "from position 1", f"({at})"]


def _wrapped_caption(mech, phrases: list[str], trajectories: Sequence[str], compact: bool) -> str:
    """Whole phrases to a line while they fit, then what the dashed lines are."""
    import textwrap

    width = COMPACT_CHARS if compact else CAPTION_CHARS
    lines = [""]
    for phrase in phrases:   # whole phrases to a line while they fit
        if lines[-1] and len(lines[-1]) + 1 + len(phrase) > width:
            lines.append(phrase)
        else:
            lines[-1] = f"{lines[-1]} {phrase}".strip()
    if trajectories and not compact:
        lines += textwrap.wrap(trajectory_note(mech, trajectories), width)
    return "\n".join(lines)


#: characters per line of a caption above a drawing (10 pt, from the axes' left edge to the page's)
CAPTION_CHARS = 62
#: characters per line of a caption above a panel of a grid of drawings (9 pt, centred)
COMPACT_CHARS = 40


def trajectory_note(mech: Mechanism, trajectories: Sequence[str]) -> str:
    over = "over the input range" if mech.input_range is not None else "over a turn"
    return f"dashed: trajectory of {', '.join(trajectories)} {over}"
