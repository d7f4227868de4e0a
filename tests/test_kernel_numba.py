"""The numba kinematics kernel (linkage/kinematics/kernel_numba.py, the ``fast`` extra) against the
general path (issue 24).

The oracle is the general path (``run_blocks`` and each group's ``Dyad.solve``, as
tests/test_kernel.py's ``general``). For every shipped closed-form scheme on its declared and its
flipped branches, at random angles over its travel and at the angles next to each group's least
conditioning and status changes, and for the edge mechanisms of the dyad kinds at their singular
positions, the numba kernel must give the same statuses (each group's and the mechanism's) and
signs, conditioning to 1e-13, and poses, analogs and error bounds to 1e-13 relative to the
mechanism's size, NaN at the same positions -- tests/test_kernel.py's ``assert_same``. Order 2
only: its kernel holds every operation of orders 0 and 1 (numba compiles a kernel in about two
seconds; numba keeps them in ``~/.cache/linkage/kernels`` for the next run).

Skipped where numba is not installed.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import warnings
import zlib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("numba", reason="the fast extra (numba) is not installed: pip install \".[fast]\"")

sys.path.insert(0, str(Path(__file__).resolve().parent))

import linkage  # noqa: E402
from linkage.kinematics import kernel_numba  # noqa: E402
from linkage.kinematics.assembly import assembly_plans  # noqa: E402
from linkage.kinematics.kernel import Kernel, kernel_for  # noqa: E402
from linkage.kinematics.kernel_numba import TieredKernel, scalar_source  # noqa: E402
from linkage.kinematics.motion import BranchWarning  # noqa: E402
from linkage.structure import structure_of  # noqa: E402

import _edge_mechanisms as E  # noqa: E402
from test_kernel import CLOSED_FORM_SCHEMES, NEAR, assert_same, flipped, general, travel  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def numba_now(monkeypatch):
    """Every kernel made in a test moves to numba at its first call."""
    monkeypatch.setenv("LINKAGE_NUMBA", "1")


def by_numba(mech, phi, branches):
    """The numba kernel's results at ``phi`` on ``branches`` (asserting it is numba that ran)."""
    kernel = kernel_for(mech, 2)
    fn = kernel.function(branches)[0]
    assert isinstance(fn, TieredKernel) and fn.compile(), "the numba kernel did not compile"
    got = kernel(phi, branches)
    assert got is not None
    return got


def by_numpy(mech, phi, branches):
    """The numpy kernel's results (a kernel made with ``LINKAGE_NUMBA=0``)."""
    import os
    saved = os.environ.get("LINKAGE_NUMBA")
    os.environ["LINKAGE_NUMBA"] = "0"
    try:
        kernel = Kernel(mech, structure_of(mech), 2)
        assert not isinstance(kernel.function(branches)[0], TieredKernel)
        return kernel(phi, branches)
    finally:
        os.environ["LINKAGE_NUMBA"] = saved


def check(mech, phi, branches, what):
    """numba kernel against the general path, and the statuses against the numpy kernel's."""
    got = by_numba(mech, phi, branches)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        ref = general(mech, phi, 2, branches)
    size = float(max(np.max(g.size) for g in structure_of(mech).groups))
    assert_same(got, ref, size, f"{mech.name} numba {what}")
    numpy_kernel = by_numpy(mech, phi, branches)
    np.testing.assert_array_equal(got["status"], numpy_kernel["status"])
    for i, s in numpy_kernel["solved"].items():
        np.testing.assert_array_equal(got["solved"][i], s)
        np.testing.assert_array_equal(got["signs"][i], numpy_kernel["signs"][i])
    return ref


def near_spots(mech, rng) -> np.ndarray:
    """Angles next to each group's least conditioning and status changes on a dense sweep."""
    dense = travel(mech, 2000, rng)
    ref = general(mech, dense, 0)
    spots = []
    for i, s in ref["solved"].items():
        c = ref["conditioning"][repr(structure_of(mech).groups[i])]
        spots.append(dense[np.argmin(np.where(np.isfinite(c), c, np.inf))])
        spots += list(dense[np.flatnonzero(np.diff(s) != 0)])
    return np.sort((np.array(spots)[:, None] + np.concatenate([NEAR, -NEAR])[None, :]).ravel())


# ----------------------------------------------------------------------------------------------


#: the schemes whose flipped branches are compiled too by default (every one with LINKAGE_FUZZ): one
#: of each dyad kind
FLIPPED = ("four_bar", "slider_crank", "slotted_link", "scotch_yoke", "slotted_link_two_dyad")


@pytest.mark.parametrize("name", CLOSED_FORM_SCHEMES)
def test_shipped_schemes_both_branches(name):
    """Random angles over the travel and the angles next to where the conditioning is least and
    where a status changes, on the declared and on the flipped branches, in one call each."""
    mech = linkage.load(name)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BranchWarning)
        phi = np.concatenate([travel(mech, 200, rng), near_spots(mech, rng)])
    declared = tuple(int(p.branch) for p in assembly_plans(mech))
    cases = [(declared, "declared")]
    if name in FLIPPED or os.environ.get("LINKAGE_FUZZ"):     # each case is a numba compile (~2 s)
        cases.append((flipped(mech), "flipped"))
    for branches, what in cases:
        check(mech, phi, branches, f"{what} branches {branches}")


@pytest.mark.parametrize("case", list(E.CASES))
def test_edge_mechanisms_at_their_singular_positions(case):
    """Statuses flip between OK, singular and cannot be assembled within a few ulps of the angle:
    the numba kernel flips at the same positions as the general path."""
    edge = E.CASES[case]
    mech = linkage.loads(edge.toml)
    phi = np.sort(edge.singular_phi + np.concatenate([NEAR, -NEAR, 1e-16 * np.arange(-40, 41)]))
    ref = check(mech, phi, tuple(int(p.branch) for p in assembly_plans(mech)), "near its singular position")
    assert len(set(ref["status"].tolist())) >= 2, "the angles should straddle the singular position"


def test_scalar_semantics_are_numpy_s():
    """The scalar forms of maximum / minimum / clip / where / sign / remainder / powers / the libm
    functions agree with numpy's on the values where they differ from a naive scalar form: NaN,
    signed zeros, infinities (a one-node-per-op trace of each, compiled by numba)."""
    special = np.array([np.nan, -0.0, 0.0, 1.5, -2.5, np.inf, -np.inf, 1e-300, 7.0, -7.0])
    x, y = np.repeat(special, len(special)), np.tile(special, len(special))
    X = SimpleNamespace(op="input", args=(0,), dtype="f", uid=0)
    Y = SimpleNamespace(op="input", args=(1,), dtype="f", uid=1)
    above = SimpleNamespace(op="greater", args=(X, Y), dtype="b", uid=2)
    nodes = [X, Y, above]
    cases = {
        "maximum": ("maximum", (X, Y)), "minimum": ("minimum", (X, Y)), "clip": ("clip", (X, -1.0, 1.0)),
        "sign": ("sign", (X,)), "remainder": ("remainder", (X, 2 * math.pi)), "square": ("pow", (X, 2)),
        "reciprocal": ("pow", (X, -1)), "inverse square": ("pow", (X, -2)), "hypot": ("hypot", (X, Y)),
        "arctan2": ("arctan2", (X, Y)), "sqrt": ("sqrt", (X,)), "divide": ("divide", (X, Y)),
        "arcsin": ("arcsin", (X,)), "absolute": ("absolute", (X,)), "negative": ("negative", (X,)),
        "where": ("where", (above, X, -0.0)),
    }
    with np.errstate(all="ignore"):
        expected = {
            "maximum": np.maximum(x, y), "minimum": np.minimum(x, y), "clip": np.clip(x, -1.0, 1.0),
            "sign": np.sign(x), "remainder": np.remainder(x, 2 * math.pi), "square": x ** 2,
            "reciprocal": x ** -1, "inverse square": x ** -2, "hypot": np.hypot(x, y), "arctan2": np.arctan2(x, y),
            "sqrt": np.sqrt(x), "divide": x / y, "arcsin": np.arcsin(x), "absolute": np.abs(x), "negative": -x,
            "where": np.where(x > y, x, -0.0),
        }
    outputs = []
    for name, (op, args) in cases.items():
        node = SimpleNamespace(op=op, args=args, dtype="f", uid=len(nodes))
        nodes.append(node)
        outputs.append((name, node))
    flag = SimpleNamespace(op="where", args=(above, 1, 0), dtype="i", uid=len(nodes))
    nodes.append(flag)
    outputs.append(("flag", flag))
    trace = SimpleNamespace(graph=SimpleNamespace(nodes=nodes), outputs=outputs,
                            live=lambda: ({node.uid: [j] for j, (_, node) in enumerate(outputs)},
                                          {n.uid for n in nodes}))     # every node is needed here
    rows = list(range(len(cases))) + [0]
    source = scalar_source(trace, rows, [True] * len(cases) + [False])
    fn = kernel_numba._load(source)
    F, J = np.empty((len(cases), len(x))), np.empty((1, len(x)), dtype=np.intp)
    fn(np.ascontiguousarray(np.stack([x, y])), F, J)
    for row, name in enumerate(cases):
        want = expected[name]
        nan = np.isnan(want)
        same = np.where(nan, np.isnan(F[row]), (F[row] == want) & (np.signbit(F[row]) == np.signbit(want)))
        assert same.all(), f"{name}: {x[~same]}, {y[~same]} -> {F[row][~same]}, numpy {want[~same]}"
    np.testing.assert_array_equal(J[0], np.where(x > y, 1, 0))


def test_off_and_fallback(monkeypatch, tmp_path):
    """``LINKAGE_NUMBA=0`` keeps the numpy kernel; by default a kernel moves to numba only once the
    numpy kernel has taken as long as the switch costs; where the cache cannot be written the
    numpy kernel stays."""
    mech = linkage.load("four_bar")
    branches = tuple(int(p.branch) for p in assembly_plans(mech))
    monkeypatch.setenv("LINKAGE_NUMBA", "0")
    assert not isinstance(Kernel(mech, structure_of(mech), 2).function(branches)[0], TieredKernel)
    monkeypatch.setenv("LINKAGE_NUMBA", "")
    kernel = Kernel(mech, structure_of(mech), 2)
    fn = kernel.function(branches)[0]
    assert isinstance(fn, TieredKernel)
    kernel(np.linspace(0.0, 1.0, 12))
    assert fn.jitted is None and 0.0 < fn.spent < 0.5         # one small call: still numpy
    fn.spent = 10.0                                            # as if it had run for 10 s
    kernel(np.linspace(0.0, 1.0, 12))
    assert fn.jitted is not None
    # a cache directory that cannot be made: the numpy kernel stays, nothing is raised
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("LINKAGE_CACHE_DIR", str(blocker))
    monkeypatch.setenv("LINKAGE_NUMBA", "1")
    monkeypatch.setattr(kernel_numba, "_LOADED", {})
    kernel = Kernel(mech, structure_of(mech), 2)
    got = kernel(np.linspace(0.0, 1.0, 12))
    fn = kernel.function(branches)[0]
    assert fn.failed and fn.jitted is None and (got["status"] == 0).all()


def test_a_second_process_loads_the_compiled_kernel(tmp_path):
    """numba's cache next to the generated module: a second process loads the machine code (a
    cache hit) instead of compiling (a miss). Order 0: a small kernel, quick to compile."""
    script = ("import numpy as np, linkage\n"
              "from linkage.kinematics.kernel import kernel_for\n"
              "mech = linkage.load('slider_crank')\n"
              "k = kernel_for(mech, 0)\n"
              "k(np.linspace(0, 1, 5))\n"
              "fn = k.function(k.branches(np.zeros(1)))[0].jitted\n"
              "print(sum(fn.stats.cache_hits.values()), sum(fn.stats.cache_misses.values()))\n")
    env = {"LINKAGE_NUMBA": "1", "LINKAGE_CACHE_DIR": str(tmp_path), "PATH": "/usr/bin:/bin",
           "PYTHONPATH": str(ROOT), "HOME": str(tmp_path)}
    runs = []
    for _ in range(2):
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, cwd=ROOT)
        assert done.returncode == 0, done.stderr
        runs.append(done.stdout.split())
    assert runs == [["0", "1"], ["1", "0"]], runs        # compiled once, then loaded
    assert list((tmp_path / "linkage" / "kernels" / "__pycache__").glob("*.nbi"))
