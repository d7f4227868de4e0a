"""The four-bar of ``schemes/four_bar.toml`` in pylinkage 1.3.0, timed on request.

Run by ``benchmarks/run.py`` with the python of a venv that holds pylinkage (with or without
numba), never imported by the project. It talks one JSON object a line:

- argv: ``--reference PATH``, once per number of positions N (an ``.npz`` written by run.py:
  ``phi`` (N,) uniform from 0, our ``A``, ``B``, ``E`` (N, 2) positions, m, and their first /
  second analogs ``dA``, ``ddA``...);
- first line written: ``{"ready": ..., "numba": bool, "check": {"N": {...}}}`` with, per N, the
  largest differences between pylinkage's results and ours (positions, velocities, accelerations);
- then for each line read, ``{"task": "kinematics" | "positions" | "kinematics_points", "n": N,
  "calls": k}``, the task is run k times at N positions and ``{"task": ..., "seconds": s}`` is
  written, s the mean duration of one call; ``{"task": "quit"}`` ends.

Run.py keeps this process alive for the whole benchmark and asks for one run per paired round,
so a peer's run and ours in the same round see the same machine load; at small N a run is many
calls (one call at N = 12 takes microseconds), timed together and divided.

What pylinkage computes (its own API, ``simulation.Linkage``):

- positions: ``Linkage.step_fast(iterations=N)``, the crank turned by ``2 pi / N`` per step
  from ``phi = 0``; B is the circle-circle intersection nearest to B of the step before (the
  branch is chosen once, at the start: B on the left of A -> C); E a ``FixedDyad`` 0.15 m from
  A at 30 deg CCW from AB; result (N, 5, 2) for O, C, A, B, E;
- full kinematics: ``Linkage.step_fast_with_kinematics(iterations=N)`` with
  ``set_input_velocity(crank, omega=1, alpha=0)``: positions, velocities and accelerations of
  the joints (with omega = 1 rad/s and eps = 0 these are the first and second analogs), then,
  since pylinkage gives no link angles, the angles of links 2 (AB) and 3 (CB) and their first
  and second derivatives from the points, vectorised numpy (``theta = atan2(r)``,
  ``omega = (r x v) / |r|^2``, ``eps = (r x a) / |r|^2`` with ``r``, ``v``, ``a`` the relative
  position, velocity and acceleration of B to A or C). ``kinematics_points`` times the pylinkage
  call alone.

Without numba (its ``numba`` extra not installed) pylinkage replaces ``numba.njit`` with a
no-op and the same functions run as plain Python; the plain figure is the faster of
``step_fast_with_kinematics`` and the per-object generator ``step_with_derivatives``
(``--plain-path auto``, the default, times both over 2000 steps at start-up and keeps the
faster; ``fast`` or ``generator`` force one). With numba the path is always ``fast``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

import numpy as np

OA, AB, CB = 0.1, 0.3, 0.25
C_POINT = (0.3, 0.0)
E_DISTANCE, E_ANGLE = 0.15, math.radians(30.0)


def rrr_left(ax: float, ay: float, cx: float, cy: float, ab: float, cb: float) -> tuple[float, float]:
    """The point B at ``ab`` from A and ``cb`` from C, on the left of the directed line A -> C (m)."""
    dx, dy = cx - ax, cy - ay
    d2 = dx * dx + dy * dy
    along = (ab * ab - cb * cb + d2) / (2.0 * d2)
    h = math.sqrt(ab * ab / d2 - along * along)
    return ax + along * dx - h * dy, ay + along * dy + h * dx


def build(n: int):
    """The four-bar in pylinkage's component API, set to give phi = 2 pi k / n at step k.

    Returns
    -------
    linkage, crank, initial coordinates (list of (x, y) per component)
    """
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage

    step = 2.0 * math.pi / n
    start = -step                                      # the first step turns the crank to phi = 0
    ax, ay = OA * math.cos(start), OA * math.sin(start)
    bx, by = rrr_left(ax, ay, C_POINT[0], C_POINT[1], AB, CB)
    o = Ground(0.0, 0.0, name="O")
    c = Ground(C_POINT[0], C_POINT[1], name="C")
    crank = Crank(anchor=o, radius=OA, angular_velocity=step, initial_angle=start, name="A")
    b = RRRDyad(anchor1=crank.output, anchor2=c, distance1=AB, distance2=CB, x=bx, y=by, name="B")
    e = FixedDyad(anchor1=crank.output, anchor2=b, distance=E_DISTANCE, angle=E_ANGLE, name="E")
    linkage = Linkage([o, c, crank, b, e], name="four_bar")
    linkage.set_input_velocity(crank, omega=1.0, alpha=0.0)
    return linkage, crank, linkage.get_coords()


def link_angles(pos: np.ndarray, vel: np.ndarray, acc: np.ndarray) -> dict[str, np.ndarray]:
    """Angles of links 2 (A -> B) and 3 (C -> B) and their derivatives from the joints' motion.

    Parameters
    ----------
    pos, vel, acc : ndarray, shape (N, 5, 2)
        Positions (m), velocities (m/s) and accelerations (m/s^2) of O, C, A, B, E.

    Returns
    -------
    dict of ``theta2, omega2, eps2, theta3, omega3, eps3``, each (N,), rad, rad/s, rad/s^2.
    """
    out = {}
    for name, base in (("2", 2), ("3", 1)):
        r = pos[:, 3] - pos[:, base]
        v = vel[:, 3] - vel[:, base]
        a = acc[:, 3] - acc[:, base]
        r2 = r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1]
        out["theta" + name] = np.arctan2(r[:, 1], r[:, 0])
        out["omega" + name] = (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0]) / r2
        out["eps" + name] = (r[:, 0] * a[:, 1] - r[:, 1] * a[:, 0]) / r2
    return out


def run_generator(linkage, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Full kinematics through the per-object generator ``step_with_derivatives`` (N, 5, 2) x 3."""
    pos = np.empty((n, 5, 2))
    vel = np.empty((n, 5, 2))
    acc = np.empty((n, 5, 2))
    for k, (p, v, a) in enumerate(linkage.step_with_derivatives(iterations=n)):
        pos[k] = p
        vel[k] = v
        acc[k] = a
    return pos, vel, acc


class Peer:
    """One pylinkage four-bar over N positions and the tasks run.py can time."""

    def __init__(self, n: int, plain_path: str) -> None:
        self.n = n
        self.linkage, self.crank, self.start = build(n)
        self.plain_path = plain_path

    def kinematics_points(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        self.linkage.set_coords(self.start)
        if self.plain_path == "generator":
            return run_generator(self.linkage, self.n)
        return self.linkage.step_fast_with_kinematics(iterations=self.n)

    def kinematics(self) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], dict]:
        pos, vel, acc = self.kinematics_points()
        return (pos, vel, acc), link_angles(pos, vel, acc)

    def positions(self) -> np.ndarray:
        self.linkage.set_coords(self.start)
        return self.linkage.step_fast(iterations=self.n)

    def timed(self, task: str, calls: int = 1) -> float:
        """The mean duration of ``calls`` calls of ``task`` timed together, s."""
        fn = {"kinematics": self.kinematics, "positions": self.positions,
              "kinematics_points": self.kinematics_points}[task]
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        return (time.perf_counter() - t0) / calls


def largest_difference(ours: np.ndarray, theirs: np.ndarray) -> float:
    """Largest absolute difference, NaN where either side is not finite."""
    both = np.isfinite(ours) & np.isfinite(theirs)
    if not both.all():
        return math.nan
    return float(np.max(np.abs(ours - theirs)))


def check(peer: Peer, ref) -> dict:
    """Largest differences of pylinkage's positions, velocities and accelerations to ours (m, m/rad...)."""
    (pos, vel, acc), _ = peer.kinematics()
    traj = peer.positions()
    out = {"positions_step_fast": max(largest_difference(ref[p], traj[:, k]) for k, p in ((2, "A"), (3, "B"), (4, "E")))}
    for label, arr, prefix in (("positions", pos, ""), ("first", vel, "d"), ("second", acc, "dd")):
        out[label] = max(largest_difference(ref[prefix + p], arr[:, k]) for k, p in ((2, "A"), (3, "B"), (4, "E")))
    return out


def phi_is_uniform(phi: np.ndarray) -> bool:
    n = len(phi)
    return bool(n > 1 and np.allclose(phi, 2.0 * np.pi * np.arange(n) / n, rtol=0, atol=1e-12))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", required=True, action="append",
                        help="npz with phi, A, B, E, dA, ... (run.py writes it), once per N")
    parser.add_argument("--plain-path", choices=("auto", "fast", "generator"), default="auto",
                        help="which pylinkage path gives full kinematics without numba (with numba: fast)")
    args = parser.parse_args(argv)
    refs = [np.load(path) for path in args.reference]
    if not all(phi_is_uniform(ref["phi"]) for ref in refs):
        print(json.dumps({"error": "phi must be 2 pi k / N, k = 0..N-1 (pylinkage steps the crank uniformly)"}))
        return 2
    from pylinkage._numba_compat import HAS_NUMBA

    path = "fast" if HAS_NUMBA else args.plain_path
    path_times = {}
    if path == "auto":
        path_times = {p: Peer(2000, p).timed("kinematics_points") for p in ("fast", "generator")}
        path = min(path_times, key=path_times.get)
    t0 = time.perf_counter()
    peers, agreement = {}, {}
    for ref in refs:
        n = len(ref["phi"])
        peers[n] = Peer(n, path)
        agreement[str(n)] = check(peers[n], ref)           # also compiles (numba) and warms the caches
    warm = time.perf_counter() - t0
    import pylinkage

    numba_version = None
    if HAS_NUMBA:
        import numba
        numba_version = numba.__version__
    print(json.dumps({"ready": True, "numba": HAS_NUMBA, "numba_version": numba_version,
                      "pylinkage": pylinkage.__version__, "numpy": np.__version__, "path": path,
                      "path_times_2000_s": path_times, "check": agreement, "warmup_s": warm}), flush=True)
    for line in sys.stdin:
        request = json.loads(line)
        task = request.get("task")
        if task == "quit":
            break
        n = int(request["n"])
        if n not in peers:
            print(json.dumps({"error": f"no reference for N = {n} (have {sorted(peers)})"}), flush=True)
            continue
        seconds = peers[n].timed(task, int(request.get("calls", 1)))
        print(json.dumps({"task": task, "n": n, "seconds": seconds}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
