"""Edge mechanisms of every dyad kind and their high-precision references (mpmath).

Each case is a crank followed by one dyad that reaches a singular (toggle / parallel-guide)
position, declared in TOML, plus an independent closed form of its outputs written in mpmath
(derivatives by ``mpmath.diff`` at 50 digits). Used by the status-OK guarantee tests and by
``benchmarks/bench_guarantee.py``; nothing here calls the library's solvers.

Every reference returns, for one input angle (or one design parameter), a dict
``quantity -> (value, first analog, second analog)`` of the dyad's outputs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import mpmath as mp

from _texts import four_bar_toml, slider_crank_toml

mp.mp.dps = 50


@dataclass(frozen=True)
class EdgeCase:
    kind: str
    toml: str
    singular_phi: float          # input angle of the singular position (rad)
    side: int                    # +1: regular positions at phi > singular_phi, -1: below
    group_scale: float           # the dyad's joint spacing (m), for scaled errors
    reference: Callable[[mp.mpf], dict[str, mp.mpf]]   # phi -> quantity values (mp)


def _derivatives(f: Callable[[mp.mpf], dict], phi: float) -> dict[str, tuple[float, float, float]]:
    x = mp.mpf(phi)
    names = f(x).keys()
    out = {}
    for q in names:
        g = (lambda t, q=q: f(t)[q])
        out[q] = tuple(float(mp.diff(g, x, n)) for n in (0, 1, 2))
    return out


def relative_errors(motion, ref) -> tuple[float, float]:
    """Largest errors of a single-position motion's first and second analogs against ``ref``,
    relative to the largest first analog (at least 1) and the largest second analog."""
    scale1 = max(max(abs(v[1]) for v in ref.values()), 1.0)
    scale2 = max(max(abs(v[2]) for v in ref.values()), scale1)
    e1 = max(abs(motion.quantity(q)[1][0] - v[1]) for q, v in ref.items()) / scale1
    e2 = max(abs(motion.quantity(q)[2][0] - v[2]) for q, v in ref.items()) / scale2
    return e1, e2


def reference(case: EdgeCase, phi: float) -> dict[str, tuple[float, float, float]]:
    """``quantity -> (value, q', q'')`` at ``phi`` from the mpmath closed form."""
    return _derivatives(case.reference, phi)


# ----------------------------------------------------------------------------------------------
# RRR: the non-Grashof four-bar (crank 1, coupler 1.2, rocker 1, ground 2)
# ----------------------------------------------------------------------------------------------
RRR_TOML = four_bar_toml(1.0, 1.2, 1.0, 2.0, name="rrr_edge")


def _rrr(phi):
    ax, ay = mp.cos(phi), mp.sin(phi)
    cx, cy = mp.mpf(2), mp.mpf(0)
    dx, dy = cx - ax, cy - ay
    d = mp.sqrt(dx**2 + dy**2)
    ex, ey = dx / d, dy / d
    l2, l3 = mp.mpf("1.2"), mp.mpf(1)
    a = (l2**2 - l3**2 + d**2) / (2 * d)
    h = mp.sqrt(l2**2 - a**2)
    bx, by = ax + a * ex - h * ey, ay + a * ey + h * ex
    return {"B.x": bx, "B.y": by, "2.theta": mp.atan2(by - ay, bx - ax),
            "3.theta": mp.atan2(by - cy, bx - cx)}


# ----------------------------------------------------------------------------------------------
# RRP: slider-crank whose rod (0.6) is shorter than the crank (1): toggle at sin(phi) = 0.6
# ----------------------------------------------------------------------------------------------
RRP_TOML = slider_crank_toml(1.0, 0.6, name="rrp_edge")


def _rrp(phi):
    ax, ay = mp.cos(phi), mp.sin(phi)
    bx = ax + mp.sqrt(mp.mpf("0.36") - ay**2)
    return {"B.x": bx, "2.theta": mp.atan2(-ay, bx - ax)}


# ----------------------------------------------------------------------------------------------
# RPR: slotted link pivoted at C = (2, 0) whose slot runs 1.5 m from C: toggle at |AC| = 1.5
# ----------------------------------------------------------------------------------------------
RPR_TOML = """
name = "rpr_edge"
input = "1"
[links.0]
points = { O = [0.0, 0.0], C = [2.0, 0.0] }
[links.1]
line = ["O", "A"]
length = 1.0
[links.2]
points.A = [0.0, 0.0]
[links.3]
points = { C = [0.0, 0.0] }
guides.slot = { through = "C", angle_deg = 0, offset = 1.5 }
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.slot]
kind = "P"
links = ["3", "2"]
guide = "slot"
at = "A"
[pairs.C]
links = ["3", "0"]
[assembly.A]
branch = 1
"""


def _rpr(phi):
    ax, ay = mp.cos(phi), mp.sin(phi)
    vx, vy = ax - 2, ay
    d2 = vx**2 + vy**2
    e = mp.mpf("1.5")
    s = mp.sqrt(d2 - e**2)            # the branch with A ahead of the foot of C along the slot
    theta3 = mp.atan2(vy, vx) - mp.atan2(e, s)
    return {"3.theta": theta3, "slot.s": s}


# ----------------------------------------------------------------------------------------------
# PRP: slider 2 on the frame's x axis, slider 3 on a guide of the crank offset by 0.5 from O;
# the guides are parallel at phi = 0 (B = (-0.5 / sin(phi), 0) runs away)
# ----------------------------------------------------------------------------------------------
PRP_TOML = """
name = "prp_edge"
input = "1"
[links.0]
points = { O = [0.0, 0.0] }
guides.rail = { through = [0.0, 0.0], angle_deg = 0 }
[links.1]
points = { O = [0.0, 0.0] }
guides.arm = { through = "O", angle_deg = 0, offset = 0.5 }
[links.2]
points.B = [0.0, 0.0]
[links.3]
points.B = [0.0, 0.0]
[pairs.O]
links = ["0", "1"]
[pairs.rail]
kind = "P"
links = ["0", "2"]
guide = "rail"
at = "B"
[pairs.arm]
kind = "P"
links = ["1", "3"]
guide = "arm"
at = "B"
[pairs.B]
links = ["2", "3"]
"""


def _prp(phi):
    return {"B.x": -mp.mpf("0.5") / mp.sin(phi)}


# ----------------------------------------------------------------------------------------------
# RPP: Scotch yoke whose slot makes the angle gamma with the rail; singular as gamma -> 0.
# Here the input angle is fixed and the reference is a function of phi for one gamma.
# ----------------------------------------------------------------------------------------------
def rpp_toml(gamma_deg: float) -> str:
    return f"""
name = "rpp_edge"
input = "1"
[links.0]
points = {{ O = [0.0, 0.0] }}
guides.rail = {{ through = [0.0, 0.0], angle_deg = 0 }}
[links.1]
line = ["O", "A"]
length = 1.0
[links.2]
points.A = [0.0, 0.0]
[links.3]
points = {{ K = [0.0, 0.0] }}
guides.slot = {{ through = "K", angle_deg = {gamma_deg!r} }}
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.slot]
kind = "P"
links = ["3", "2"]
guide = "slot"
at = "A"
[pairs.rail]
kind = "P"
links = ["0", "3"]
guide = "rail"
at = "K"
"""


def rpp_reference(gamma_deg: float):
    gamma = mp.radians(mp.mpf(gamma_deg))

    def f(phi):
        ax, ay = mp.cos(phi), mp.sin(phi)
        return {"K.x": ax - ay * mp.cot(gamma)}

    return f


CASES = {
    "RRR": EdgeCase("RRR", RRR_TOML, float(mp.acos(mp.mpf("0.04"))), -1, 1.2, _rrr),
    "RRP": EdgeCase("RRP", RRP_TOML, float(mp.asin(mp.mpf("0.6"))), -1, 0.6, _rrp),
    "RPR": EdgeCase("RPR", RPR_TOML, float(mp.acos(mp.mpf("0.6875"))), 1, 1.5, _rpr),
    "PRP": EdgeCase("PRP", PRP_TOML, 0.0, 1, 0.5, _prp),
}


# ----------------------------------------------------------------------------------------------
# a chain: the RRR four-bar above drives a rod D-E and a slider E on the line y = -1
# (D is the middle of the rocker CB), so the toggle's round-off reaches a second group
# ----------------------------------------------------------------------------------------------
CHAIN_TOML = RRR_TOML.replace('''[links.3]
line = ["C", "B"]
length = 1.0''', '''[links.3]
line = ["C", "B"]
length = 1.0
points.D = { from = "C", distance = 0.5 }
[links.4]
line = ["D", "E"]
length = 1.5
[links.5]
points.E = [0.0, 0.0]''').replace('''[links.0]
points = { O = [0.0, 0.0], C = [2.0, 0.0] }''', '''[links.0]
points = { O = [0.0, 0.0], C = [2.0, 0.0] }
guides.low = { through = [0.0, -1.0], angle_deg = 0 }''') + '''
[pairs.D]
links = ["3", "4"]
[pairs.E]
links = ["4", "5"]
[pairs.low]
kind = "P"
links = ["0", "5"]
guide = "low"
at = "E"
[assembly.E]
from = "D"
towards_deg = 0
'''


def _chain(phi):
    out = _rrr(phi)
    th3 = out["3.theta"]
    dx, dy = 2 + mp.mpf("0.5") * mp.cos(th3), mp.mpf("0.5") * mp.sin(th3)
    out["E.x"] = dx + mp.sqrt(mp.mpf("2.25") - (dy + 1) ** 2)
    return out


CHAIN = EdgeCase("RRR+RRP", CHAIN_TOML, CASES["RRR"].singular_phi, -1, 1.5, _chain)
