"""Course assignments: what a teacher hands out, built from any stage below.

Templates whose values are expressions of parameters (:mod:`~.template`), variants drawn from
them, checked for feasibility and written as folders of sheets and answer keys
(:mod:`~.variants`), and the sheets themselves (:mod:`~.sheets`). Reads the model, the
kinematics' feasibility rules and the report's tables and results.
"""
