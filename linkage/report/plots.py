"""Pictures for people: diagrams of table columns and the mechanism drawn to scale.

This module is the public face of the pictures (``from linkage.report.plots import
draw_mechanism``); they live in :mod:`linkage.report.diagrams` (diagrams),
:mod:`linkage.report.drawing` (the mechanism to scale), :mod:`linkage.report.words` (the columns
and links in words) and :mod:`linkage.report.style` (matplotlib, fonts, colours).

Needs the ``plot`` extra (matplotlib). Without it the rest of the library works, and every
function here raises :class:`PlotExtraMissing` (a :class:`~linkage.errors.LinkageError` and an
``ImportError``) saying ``pip install "linkage[plot]"`` (:data:`INSTALL_HINT`).

Diagrams (the x axis is ``phi_deg``, the input angle turned from position 1):

- :func:`plot_columns` -- table columns of one unit on one set of axes: axes labelled with the
  quantity in words and its unit, legends in words (:func:`describe_column`), the table positions
  marked on the curves and numbered along the top, extreme positions of the output
  (:func:`extreme_marks`) and the mean driving moment drawn when given, angle columns made
  continuous;
- :func:`plot_diagrams` -- several columns, one panel per unit, over a shared angle axis;
- :func:`plot_motion` -- kinematic diagrams of a :class:`~linkage.Motion` over its table positions
  (smooth curves from a fine analysis, the extreme positions of the output marked);
- :func:`plot_dynamics` -- per-position columns of a dynamics report (the balancing moment with the
  mean driving moment, ω, ε ...).

Drawings of the mechanism, to scale (equal aspect, axes in m), fully inside the frame:

- :func:`draw_mechanism` -- one position: links as lines and polygons, revolute pairs as circles,
  sliders as blocks along their guides, guides and slots, frame pivots and guides hatched, point
  labels placed where they collide with nothing, trajectories of named points;
- :func:`draw_positions` -- several positions side by side at one common scale.

Words: :func:`describe_column` (a column in words, :class:`ColumnWords`), :func:`link_role`,
:func:`unit_for_people`.

Every function returns the matplotlib ``Figure`` or ``Axes``; save with ``fig.savefig("a.png")``
or ``"a.svg"``.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import numpy as np, linkage
>>> from linkage.report.plots import draw_mechanism
>>> motion = linkage.analyze(linkage.load("slotted_link_two_dyad"), np.radians([30.0]))
>>> ax = draw_mechanism(motion, 0)
>>> ax.get_xlabel(), ax.get_ylabel()
('x, m', 'y, m')
>>> matplotlib.pyplot.close("all")
"""

from __future__ import annotations

from .diagrams import extreme_marks, plot_columns, plot_diagrams, plot_dynamics, plot_motion
from .drawing import draw_mechanism, draw_positions
from .style import INSTALL_HINT, PlotExtraMissing
from .words import ColumnWords, describe_column, link_role, unit_for_people

__all__ = ["PlotExtraMissing", "INSTALL_HINT", "ColumnWords", "describe_column", "link_role", "unit_for_people",
           "extreme_marks", "plot_columns", "plot_diagrams", "plot_motion", "plot_dynamics", "draw_mechanism",
           "draw_positions"]
