"""A press whose motor runs it but cannot start it from rest (issue 21, "commands that give up half-way").

The press below (a central slider-crank, the pressing force over the last half of the stroke
towards +x) has an induction motor whose breakdown moment carries the steady state, but whose
starting torque (0.59 of the rated one, overload 1.6) is far below the press's peak resistance:
started from rest, the machine stalls late in the first turn. The commands still finish their
main job: ``linkage dynamics --method ode`` prints the steady state and says where the start-up
stalls; ``linkage report`` writes index.html with the start-up drawn up to the stall and a note.

The oracle is the test's own integration of the equation of motion in time,
``I(psi) domega/dt = M_d(omega) + M_red(psi) - I'(psi) omega^2 / 2``, ``dpsi/dt = omega``, from
the reduced moment and inertia of :func:`reduced_characteristics` on a grid 5 times finer than the
library's, the motor by Kloss written out here, until omega returns to zero.
"""

from __future__ import annotations

import html
import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

import linkage
from linkage.cli import main
from linkage.dynamics.cycle import exact_method
from linkage.dynamics.equation import StartupStall, simulate
from linkage.dynamics.reduced import reduced_characteristics
from linkage.dynamics.spec import dynamics_of
from linkage.errors import DynamicsError

RPM = 2 * math.pi / 60

#: the motor (induction, through a gearbox) and the start speed, appended to PRESS
MOTOR = """
[dynamics.motor]
kind = "induction"
rated_power = 250.0
synchronous_rpm = 1500
rated_rpm = 1400
overload = 1.6
ratio = 23.5
efficiency = 0.9
"""

PRESS = """
name = "press_stall"
description = "Slider-crank press: crank OA = 0.1 m, rod AB = 0.4 m, ram B on a horizontal guide through O"
input = "1"
output = { quantity = "B.x", start = "max" }   # position 1: the crank along +x (phi = 0)

[links.0]
points = { O = [0.0, 0.0] }
guides.slide = { through = [0.0, 0.0], angle_deg = 0 }

[links.1]
line = ["O", "A"]
length = 0.1
mass = 10.0
com = "O"

[links.2]
line = ["A", "B"]
length = 0.4
points.S2 = { from = "A", distance = 0.13 }
mass = 12.0
com = "S2"
inertia = 0.16

[links.3]
points.B = [0.0, 0.0]
mass = 40.0
com = "B"

[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"

[assembly.B]
from = "O"
towards_deg = 0

[loads]
gravity = [0.0, -9.81]

[[loads.forces]]
point = "B"
link = "3"
diagram = { along = "x", working = "+", fractions = [0, 0.5, 0.95, 1], values = [0, 0, 2500, 10000] }

[dynamics]
mean_rpm = -60
delta = 0.05
positions = 12
inertia_0 = 0.5
cycles = 8
"""


def press_text(initial_rpm: float = 0.0, motor: bool = True) -> str:
    return PRESS + f"initial_rpm = {initial_rpm:g}\n" + (MOTOR if motor else "")


def kloss(w):
    """The motor's moment at the crank, N m, at the crank speed ``w`` (rad/s), by Kloss."""
    m_nom = 250.0 / (1400 * RPM)
    s_nom = 100 / 1500
    s_k = s_nom * (1.6 + math.sqrt(1.6**2 - 1))
    slip = (1500 - 23.5 * w / RPM) / 1500
    return 23.5 * 0.9 * 2 * 1.6 * m_nom / (slip / s_k + s_k / slip)


class Oracle:
    """The press's reduced moment and inertia on a fine grid of psi (position 1 is phi = 0, the
    crank turns clockwise: phi = -psi), and the stall of the equation of motion in time."""

    def __init__(self, mech, constant: float, steps: int = 3600):
        spec = dynamics_of(mech)
        assert spec.rotation == -1
        self.psi = np.linspace(0, 2 * np.pi, steps + 1)
        red = reduced_characteristics(mech, -self.psi, -1, extra_inertia=spec.constant_inertia)
        self.moment = red.moment
        self.inertia = CubicSpline(self.psi, constant + red.inertia_variable, bc_type="periodic")
        self.slope = CubicSpline(self.psi, red.inertia_derivative)
        # the constant moment that balances the cycle: the mean resistance over the turn
        self.balancing = -float(np.sum((self.moment[1:] + self.moment[:-1]) / 2 * np.diff(self.psi))) / (2 * np.pi)

    def m_red(self, psi):
        return np.interp(np.mod(psi, 2 * np.pi), self.psi, self.moment)

    def stall(self, driving, w0: float = 0.0) -> tuple[float, float]:
        """(psi in rad from the start, t in s) where omega falls back to 0."""

        def rhs(t, y):
            psi, w = y
            at = psi % (2 * np.pi)
            return [w, (driving(w) + self.m_red(psi) - 0.5 * float(self.slope(at)) * w * w) / float(self.inertia(at))]

        def stops(t, y):
            return y[1] if t > 1e-6 else 1.0

        stops.terminal, stops.direction = True, -1
        sol = solve_ivp(rhs, (0, 60), [0.0, w0], method="DOP853", rtol=1e-10, atol=1e-12, events=stops,
                        max_step=0.01)
        assert len(sol.t_events[0]) == 1, "the oracle's machine does not stall"
        return float(sol.y_events[0][0][0]), float(sol.t_events[0][0])


@pytest.fixture(scope="module")
def press():
    mech = linkage.loads(press_text())
    constant = exact_method(mech, dynamics_of(mech)).constant_inertia  # the flywheel for delta, as ode sizes it
    return mech, constant, Oracle(mech, constant)


STALL_WORDS = re.compile(r"stalls \(omega -> 0\) at psi = (\d+\.\d) deg of turn (\d+) .*? after t = ([0-9.]+) s")


def said_agrees(said: float, exact: float) -> bool:
    """``said`` (4 significant digits) is ``exact`` rounded, to within 1e-4 of it."""
    return abs(said - exact) <= 0.5 * 10 ** (math.floor(math.log10(exact)) - 3) + 1e-4 * exact


def said_stall(text: str) -> tuple[float, int, float]:
    found = STALL_WORDS.search(text)
    assert found, text
    return float(found[1]), int(found[2]), float(found[3])


def test_the_stall_from_rest_is_where_an_independent_integration_stops(press):
    mech, constant, oracle = press
    with pytest.raises(StartupStall) as info:
        simulate(mech, constant_inertia=constant)
    assert isinstance(info.value, DynamicsError)  # callers that catch DynamicsError still do
    stall = info.value.stall
    psi, t = oracle.stall(kloss)
    assert psi < 2 * np.pi  # the first turn
    assert math.degrees(stall.psi) == pytest.approx(math.degrees(psi), abs=0.01)
    assert stall.t == pytest.approx(t, rel=2e-4)
    assert (stall.turn, stall.degrees) == (1, pytest.approx(math.degrees(psi), abs=0.01))
    # what the numbers mean: the motor's moment at rest (Kloss at slip 1), the resistance there,
    # the largest resistance over the turn (a moment at rest above it cannot stall)
    assert stall.starting_moment == pytest.approx(kloss(0.0), rel=1e-12)
    assert stall.resisting == pytest.approx(-oracle.m_red(psi), rel=1e-3)
    assert stall.resisting > stall.starting_moment  # at omega = 0 the net moment decelerates
    k = int(np.argmax(-oracle.moment))
    assert stall.largest_resisting == pytest.approx(-oracle.moment[k], rel=1e-3)
    assert math.degrees(stall.largest_at) == pytest.approx(math.degrees(oracle.psi[k]), abs=0.6)
    assert stall.shortfall == pytest.approx(stall.largest_resisting - kloss(0.0))
    # the message says it, in the documented range of psi (0..360 deg, with the turn)
    degrees, turn, seconds = said_stall(str(info.value))
    assert turn == 1 and 0 <= degrees < 360
    assert degrees == pytest.approx(math.degrees(psi), abs=0.06)
    assert said_agrees(seconds, t)
    assert f"{stall.largest_resisting:.4g} N m" in str(info.value)
    assert f"{stall.shortfall:.4g} N m more" in str(info.value)
    # the motion up to the stall: it starts at rest and ends there, at the stall
    run = info.value.transient
    assert run.omega[0] == 0 and run.psi[-1] == pytest.approx(stall.psi) and run.t[-1] == pytest.approx(stall.t)
    assert abs(run.omega[-1]) < 1e-3 * np.max(np.abs(run.omega))


def test_a_start_at_speed_that_stalls_in_the_second_turn_names_the_turn():
    mech = linkage.loads(press_text(initial_rpm=5))
    constant = exact_method(mech, dynamics_of(mech)).constant_inertia
    with pytest.raises(StartupStall) as info:
        simulate(mech, constant_inertia=constant)
    psi, t = Oracle(mech, constant).stall(kloss, w0=5 * RPM)
    assert 2 * np.pi < psi < 4 * np.pi
    degrees, turn, seconds = said_stall(str(info.value))
    assert turn == 2 and degrees == pytest.approx(math.degrees(psi) - 360, abs=0.06)
    assert said_agrees(seconds, t)
    assert "from |omega| = 0.523599 rad/s" in str(info.value)


def test_without_a_motor_the_constant_moment_of_the_cycle_balance_is_blamed(press):
    mech = linkage.loads(press_text(motor=False))
    _, constant, oracle = press
    with pytest.raises(StartupStall) as info:
        simulate(mech, constant_inertia=constant)
    text = str(info.value)
    assert "the motor" not in text and "constant driving moment from the cycle balance" in text
    assert info.value.stall.starting_moment == pytest.approx(oracle.balancing, rel=1e-3)
    psi, t = oracle.stall(lambda w: oracle.balancing)
    degrees, turn, seconds = said_stall(text)
    assert turn == 1 and degrees == pytest.approx(math.degrees(psi), abs=0.06)
    assert said_agrees(seconds, t)


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize("motor", [True, False], ids=["induction motor", "no motor"])
def test_linkage_dynamics_ode_prints_the_steady_state_and_notes_the_stall(tmp_path, capsys, press, motor):
    _, _, oracle = press
    path = tmp_path / "press_stall.toml"
    path.write_text(press_text(motor=motor))
    code, out, err = run_cli(capsys, "dynamics", path, "--method", "ode", "--format", "csv")
    assert code == 0, err
    rows = out.strip().splitlines()
    assert rows[0].startswith("i,phi_deg") and len(rows) == 1 + 13 + (1 if rows[1].startswith("[") else 0)
    (line,) = [line for line in err.splitlines() if "stalls" in line]
    assert line.startswith("linkage: note: start-up transient: the start-up from rest stalls")
    psi, t = oracle.stall(kloss if motor else (lambda w: oracle.balancing))
    degrees, turn, seconds = said_stall(line)
    assert turn == 1 and degrees == pytest.approx(math.degrees(psi), abs=0.06)
    assert said_agrees(seconds, t)
    assert ("the motor's moment at rest" in line) == motor and ("the motor cannot" not in line)
    assert "error" not in err and "Traceback" not in err


def test_linkage_dynamics_transient_ends_at_the_stall(tmp_path, capsys, press):
    _, _, oracle = press
    path = tmp_path / "press_stall.toml"
    path.write_text(press_text())
    code, out, err = run_cli(capsys, "dynamics", path, "--method", "ode", "--transient", "--format", "csv")
    assert code == 0, err
    last = out.strip().splitlines()[-1].split(",")
    psi, t = oracle.stall(kloss)
    assert float(last[0]) == pytest.approx(t, rel=2e-4)
    assert float(last[1]) == pytest.approx(math.degrees(psi), abs=0.01)


def test_linkage_report_writes_the_page_with_the_stall_noted(tmp_path, capsys, press):
    pytest.importorskip("matplotlib")
    pytest.importorskip("jinja2")
    _, _, oracle = press
    path = tmp_path / "press_stall.toml"
    path.write_text(press_text())
    code, _, err = run_cli(capsys, "report", path, "--out", tmp_path / "report")
    assert code == 0, err
    page = tmp_path / "report" / "index.html"
    assert page.exists() and (tmp_path / "report" / "startup.png").exists()
    text = html.unescape(page.read_text())
    (note,) = [line for line in re.findall(r"<li>(.*?)</li>", text, re.DOTALL) if "stalls" in line]
    assert note.startswith("start-up diagram: the start-up from rest stalls")
    psi, t = oracle.stall(kloss)
    degrees, turn, seconds = said_stall(note)
    assert turn == 1 and degrees == pytest.approx(math.degrees(psi), abs=0.06)
    assert said_agrees(seconds, t)
    assert "linkage: note: start-up diagram: the start-up from rest stalls" in err
