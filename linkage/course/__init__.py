"""Course assignments: what a teacher hands out, built from any stage below.

Templates whose values are expressions of parameters: the expression language
(:mod:`~.expressions`), the ``[template.parameters]`` table (:mod:`~.parameters`), and the
template itself with its loading, reproducible draws and the CSV of given variants
(:mod:`~.template`); variants drawn from them, checked for feasibility and written as folders of
sheets and answer keys (:mod:`~.variants`); what a student is given, machine-readable
(:mod:`~.given`, ``given.json``); the printable PDFs: one variant's assignment sheet rendered from
it, with the mechanism drawn to scale (:mod:`~.sheets`) and the load diagrams
(:mod:`~.diagram_blocks`), the overview of all variants
(:mod:`~.overview`), and the page toolkit both are typeset with (:mod:`~.typesetting`); the
step-by-step answer key (:mod:`~.key`, ``key.json`` and ``key.csv``) and the grading of a class's
answers against it (:mod:`~.grading`, ``linkage grade``). Reads the model, the kinematics'
feasibility rules, the kinetostatics, the dynamics and the report's tables, results and drawings.
"""
