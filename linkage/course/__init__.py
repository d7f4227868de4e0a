"""Course assignments: what a teacher hands out, built from any stage below.

Templates whose values are expressions of parameters: the expression language
(:mod:`~.expressions`), the ``[template.parameters]`` table (:mod:`~.parameters`), and the
template itself with its loading, reproducible draws and the CSV of given variants
(:mod:`~.template`); variants drawn from them, checked for feasibility and written as folders of
sheets and answer keys (:mod:`~.variants`); the printable PDFs: one variant's assignment sheet
with the mechanism drawn to scale (:mod:`~.sheets`), the overview of all variants
(:mod:`~.overview`), and the page toolkit both are typeset with (:mod:`~.typesetting`). Reads the
model, the kinematics' feasibility rules and the report's tables, results and drawings.
"""
