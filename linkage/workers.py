"""Many independent calls of one function: in this process, in worker processes, or on a Dask cluster.

The course's variants (``linkage variants``) and the structural synthesis's geometry searches
(``linkage synthesize --with-geometry``) are many independent jobs; :func:`run_all` runs them where
the user asks (``--workers K`` or ``--scheduler ADDRESS``) and yields the results in order, so the
outcome never depends on where they ran.

>>> list(run_all(divmod, [(7, 2), (9, 4)]))
[(3, 1), (2, 1)]
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence

from .errors import InputError

__all__ = ["run_all"]


def run_all(function: Callable, calls: Sequence[tuple], *, workers: int = 1,
            scheduler: str | None = None) -> Iterator:
    """``function(*args)`` for each ``args`` of ``calls``, yielded in the order of ``calls``.

    Parameters
    ----------
    function : callable
        A module-level function (worker processes and Dask pickle it).
    calls : sequence of tuple
        The arguments of each call.
    workers : int
        Worker processes on this machine (1: this process).
    scheduler : str, optional
        The address of a Dask scheduler (``tcp://host:8786``; the ``dask`` extra) to run them on
        instead.

    Raises
    ------
    InputError
        Dask is not installed, or the scheduler cannot be reached.
    """
    if scheduler is not None:
        yield from _on_dask(function, calls, scheduler)
    elif workers > 1 and len(calls) > 1:
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(function, *args) for args in calls]
            for future in futures:
                yield future.result()
    else:
        for args in calls:
            yield function(*args)


def _on_dask(function: Callable, calls: Sequence[tuple], scheduler: str) -> Iterator:
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler needs Dask's distributed scheduler: pip install 'linkage[dask]'") from None
    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise InputError(f"--scheduler {scheduler}: cannot reach a Dask scheduler there ({exc})") from None
    with client:
        futures = [client.submit(function, *args, pure=False) for args in calls]
        for future in futures:
            yield future.result()
