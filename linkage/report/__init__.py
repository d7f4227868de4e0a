"""Reports: tables (text, CSV, JSON) of analysis results.

>>> import numpy as np
>>> from linkage.report import format_columns
>>> print(format_columns({"phi_deg": np.array([0.0, 90.0]), "B.x": np.array([0.25, 0.125])}, "csv"), end="")
phi_deg,B.x
0.0,0.25
90.0,0.125
"""

from .tables import FORMATS, format_columns

__all__ = ["FORMATS", "format_columns"]
