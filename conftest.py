"""Root of the test session.

Its presence puts the project's root on ``sys.path`` before anything is collected, so the tests
and the doctests of ``linkage/`` and ``assur/`` import one and the same copy of the packages
(the source tree) even after ``pip install .`` put another copy in site-packages.
"""
