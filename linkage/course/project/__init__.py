"""The course project's drawing sheets: kinematics, kinetostatics and dynamics to scale.

One drawing model (:mod:`~.model`: primitives on paper in mm, layers, regions, scales) that the
sheet composers fill from the analysis results, and the writers (:mod:`~.writers`) that turn
one drawing into PDF, SVG and DXF. Reads the model, kinematics, kinetostatics (plans, polygons,
the lever), dynamics and the report's results.
"""
