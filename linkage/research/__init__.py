"""Research: many mechanisms from one, measured side by side.

The enumeration of pair kinds over a scheme's chain (:mod:`~.enumeration`): every R/P
assignment that decomposes into solvable groups, its geometry placed, checked over a full turn
and measured. Reads every analysis stage and the report's tables.
"""
