"""The look every picture shares, and the way to matplotlib.

Pictures need the ``plot`` extra (matplotlib); the rest of the library works without it.
:func:`pyplot` is how a picture gets ``matplotlib.pyplot``: without it every picture raises
:class:`PlotExtraMissing` (a :class:`~linkage.errors.LinkageError` and an ``ImportError``) saying
:data:`INSTALL_HINT`. The sizes and colours here make the diagrams, drawings, hodographs, plans
and films look like one set: the width of an A4 page's text (:data:`PAGE_WIDTH`), the fonts
(:data:`FONT`, :data:`SMALL`), the colours of the links (:data:`LINK_COLOURS`) and of the curves
of a diagram (:data:`CURVE_COLOURS`, with their :data:`MARKERS`).

>>> from linkage.report.style import PlotExtraMissing, new_figure
>>> issubclass(PlotExtraMissing, ImportError)
True
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> fig = new_figure(PAGE_WIDTH, 3.0)
>>> fig.get_size_inches().tolist()
[6.3, 3.0]
>>> matplotlib.pyplot.close(fig)
"""

from __future__ import annotations

from ..errors import LinkageError

__all__ = ["INSTALL_HINT", "PAGE_WIDTH", "FONT", "SMALL", "LINK_COLOURS", "CURVE_COLOURS", "MARKERS",
           "PlotExtraMissing", "pyplot", "new_figure", "fit_width"]


#: what to install for pictures
INSTALL_HINT = 'pictures need matplotlib, the optional "plot" extra: pip install "linkage[plot]"'

#: figure width, inches: the text width of an A4 page with 2.5 cm margins (16 cm)
PAGE_WIDTH = 6.3
#: font sizes, points (readable when the figure is printed at PAGE_WIDTH)
FONT = 10
SMALL = 9

#: colours of the moving links (distinct in colour and when printed in grey)
LINK_COLOURS = ("#1f5fa8", "#c0392b", "#27864a", "#7d3c98", "#d35400", "#6b4f2a", "#138d90", "#b03a7a")
#: colours of the curves of a diagram
CURVE_COLOURS = ("#1f5fa8", "#c0392b", "#27864a", "#7d3c98", "#d35400", "#138d90")
MARKERS = ("o", "s", "^", "D", "v", "P")


class PlotExtraMissing(LinkageError, ImportError):
    """matplotlib is not installed: pictures need the ``plot`` extra, ``pip install "linkage[plot]"``."""


def pyplot():
    """``matplotlib.pyplot``, or :class:`PlotExtraMissing` with the install hint."""
    try:
        import matplotlib  # noqa: F401
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise PlotExtraMissing(INSTALL_HINT) from exc
    return plt


def new_figure(width: float, height: float, layout: str | None = "constrained"):
    """A new figure ``width`` by ``height`` inches, laid out by ``layout`` (constrained by default)."""
    plt = pyplot()
    return plt.figure(figsize=(width, height), layout=layout)


def fit_width(text, margin: float = 0.02) -> None:
    """Re-wrap a matplotlib Text (a title, a caption) at fewer characters a line until it is no
    wider than its figure less ``margin`` (a fraction of the width) on each side: no title runs
    off the picture. Lines already short enough are kept as they are."""
    import textwrap

    fig = text.get_figure()
    renderer = fig.canvas.get_renderer()
    room = fig.bbox.width * (1 - 2 * margin)
    original = text.get_text().split("\n")
    chars = max((len(line) for line in original), default=0)
    while chars > 20 and text.get_window_extent(renderer).width > room:
        chars = int(chars * 0.92)
        text.set_text("\n".join(part for line in original for part in (textwrap.wrap(line, chars) or [""])))
