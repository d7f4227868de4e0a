"""The results of a kinematics kernel (:mod:`linkage.kinematics.kernel`) as mappings of views.

A kernel writes every result of a call into the rows of one ``(R, N)`` float array. The poses and
analogs of each link and the points of each link are read through the two mappings here, which
make a view of the rows a key names when it is first asked for: a call at a few positions then
does not pay for the views nobody reads.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["LinkRows", "PointRows"]


class LinkRows(Mapping):
    """The poses (or analogs of one order) of a kernel's results, link -> ``(N, 3)``, as views of
    three of its rows each, made when first asked (a call at a few positions does not pay for
    the links nobody reads)."""

    __slots__ = ("_floats", "_start", "_index", "_views")

    def __init__(self, floats: np.ndarray, start: int, index: dict[str, int]):
        self._floats, self._start, self._index, self._views = floats, start, index, {}

    def __getitem__(self, link: str) -> np.ndarray:
        view = self._views.get(link)
        if view is None:
            row = self._start + 3 * self._index[link]
            view = self._views[link] = self._floats[row:row + 3].T
        return view

    def block(self, links) -> np.ndarray | None:
        """The rows of ``links`` as one ``(L, 3, N)`` view where their rows are consecutive in
        this order (a group's links: the kernel writes them so), else None."""
        first = self._index[links[0]]
        if any(self._index[k] != first + i for i, k in enumerate(links)):
            return None
        row = self._start + 3 * first
        return self._floats[row:row + 3 * len(links)].reshape(len(links), 3, -1)

    def __contains__(self, link) -> bool:
        return link in self._index

    def __iter__(self):
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)


class PointRows(Mapping):
    """The points of a kernel's results, ``(link, local point)`` -> position and first and second
    analogs ``(N, 2)`` (None above the order), as views of its rows made when asked."""

    def __init__(self, floats: np.ndarray, rows: dict, order: int):
        self._floats, self._rows, self._order = floats, rows, order

    def __getitem__(self, key):
        floats, rows, order = self._floats, self._rows[key], self._order
        return (floats[rows[0]:rows[0] + 2].T, floats[rows[1]:rows[1] + 2].T if order >= 1 else None,
                floats[rows[2]:rows[2] + 2].T if order == 2 else None)

    def get(self, key, default=None):
        return self[key] if key in self._rows else default

    def __iter__(self):
        return iter(self._rows)

    def __len__(self) -> int:
        return len(self._rows)
