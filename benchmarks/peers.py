"""The peer libraries run.py measures against: their venvs and their long-lived worker processes.

A peer is never a dependency of the project: each lives in a venv the benchmark creates under
``benchmarks/.venvs/`` (git-ignored) on first use and reuses afterwards, and is driven through
``benchmarks/peer_worker.py`` running on that venv's python. The worker stays alive for the
whole benchmark and runs one timed task per request, so run.py can put a peer's run in the same
paired round as ours.
"""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parent
VENV_ROOT = BENCH_DIR / ".venvs"
WORKER = BENCH_DIR / "peer_worker.py"
PYLINKAGE = "pylinkage==1.3.0"

#: venv name -> what pip installs in it (numba is pylinkage's optional ``numba`` extra).
PEER_VENVS: dict[str, tuple[str, ...]] = {
    "pylinkage_numba": (PYLINKAGE, "numba"),
    "pylinkage_plain": (PYLINKAGE,),
}


class PeerUnavailable(RuntimeError):
    """A peer could not be installed or started; the message says why."""


@dataclass
class VenvJob:
    """A venv being created in the background (``python -m venv`` then ``pip install``)."""

    name: str
    path: Path
    requirements: tuple[str, ...]
    process: subprocess.Popen | None
    log: Path
    started: float

    @property
    def python(self) -> Path:
        return self.path / "bin" / "python"

    @property
    def marker(self) -> Path:
        return self.path / "installed.txt"


def _ready(job: VenvJob) -> bool:
    return job.marker.is_file() and job.marker.read_text().split() == list(job.requirements)


def start_venv(name: str, root: Path = VENV_ROOT, env: dict | None = None) -> VenvJob:
    """Start creating the venv ``name`` of :data:`PEER_VENVS` unless it is already complete.

    Returns at once; :func:`finish_venv` waits for it. A venv whose ``installed.txt`` does not
    list exactly the wanted requirements is rebuilt from scratch.
    """
    requirements = PEER_VENVS[name]
    path = root / name
    root.mkdir(parents=True, exist_ok=True)
    job = VenvJob(name, path, requirements, None, root / f"{name}.log", time.perf_counter())
    if _ready(job):
        return job
    script = (f'rm -rf "{path}" && "{sys.executable}" -m venv "{path}" && '
              f'"{path}/bin/python" -m pip install --disable-pip-version-check --no-input -q '
              + " ".join(f'"{r}"' for r in requirements))
    with open(job.log, "w") as log:
        job.process = subprocess.Popen(["bash", "-c", script], stdout=log, stderr=subprocess.STDOUT,
                                       stdin=subprocess.DEVNULL, env=env)
    return job


def finish_venv(job: VenvJob, timeout: float) -> Path:
    """Wait for ``job``; the venv's python, or :class:`PeerUnavailable` with pip's last lines."""
    if job.process is not None:
        try:
            code = job.process.wait(timeout=max(1.0, timeout - (time.perf_counter() - job.started)))
        except subprocess.TimeoutExpired:
            job.process.kill()
            job.process.wait()
            raise PeerUnavailable(f"creating venv {job.path} took more than {timeout:.0f} s") from None
        if code != 0:
            tail = " | ".join(job.log.read_text(errors="replace").strip().splitlines()[-3:])
            raise PeerUnavailable(f"pip install {' '.join(job.requirements)} into {job.path} failed "
                                  f"(exit {code}): {tail}")
        job.marker.write_text(" ".join(job.requirements) + "\n")
    if not job.python.is_file():
        raise PeerUnavailable(f"{job.python} is missing")
    return job.python


class PeerWorker:
    """One ``peer_worker.py`` process: warm-up and agreement check, then timed tasks on request.

    Parameters
    ----------
    python : Path
        The python of the peer's venv.
    references : list of Path
        The ``.npz`` of our reference results, one per number of positions N (see ``peer_worker.py``).
    env : dict
        Environment of the process (``OMP_NUM_THREADS=1`` ...).
    """

    def __init__(self, python: Path, references: list[Path], env: dict) -> None:
        self.stderr_path = references[0].with_name(f"{Path(python).parent.parent.name}.stderr")
        self._stderr = open(self.stderr_path, "w")  # noqa: SIM115 - open for the process's lifetime
        argv = [str(python), str(WORKER)]
        for reference in references:
            argv += ["--reference", str(reference)]
        self.process = subprocess.Popen(argv,
                                        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
                                        text=True, env=env, cwd=str(BENCH_DIR))
        self._lines: queue.Queue = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self.info: dict | None = None

    def _read(self) -> None:
        for line in self.process.stdout:
            self._lines.put(line)
        self._lines.put(None)

    def _reply(self, timeout: float) -> dict:
        try:
            line = self._lines.get(timeout=timeout)
        except queue.Empty:
            self.close()
            raise PeerUnavailable(f"the peer worker did not answer within {timeout:.0f} s") from None
        if line is None:
            self.close()
            tail = " | ".join(self.stderr_path.read_text(errors="replace").strip().splitlines()[-3:])
            raise PeerUnavailable(f"the peer worker stopped (exit {self.process.returncode}): {tail}")
        reply = json.loads(line)
        if "error" in reply:
            raise PeerUnavailable(f"the peer worker refused: {reply['error']}")
        return reply

    def wait_ready(self, timeout: float) -> dict:
        """The worker's first line: versions, the path it uses, agreement with our results."""
        self.info = self._reply(timeout)
        return self.info

    def seconds(self, task: str, n: int, calls: int = 1, timeout: float = 900.0) -> float:
        """Run ``task`` ``calls`` times at ``n`` positions in the worker; the mean duration of one
        call measured there, s."""
        self.process.stdin.write(json.dumps({"task": task, "n": n, "calls": calls}) + "\n")
        self.process.stdin.flush()
        return float(self._reply(timeout)["seconds"])

    def close(self) -> None:
        if self.process.poll() is None:
            try:
                self.process.stdin.write(json.dumps({"task": "quit"}) + "\n")
                self.process.stdin.flush()
                self.process.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.process.kill()
                self.process.wait()
        self._stderr.close()


def subprocess_env() -> dict:
    """This process's environment with one thread for every numeric library."""
    env = dict(os.environ)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        env[var] = "1"
    return env
