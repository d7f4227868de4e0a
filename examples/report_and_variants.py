"""A report of a shipped scheme and a set of course assignments, from Python.

Run: ``python examples/report_and_variants.py [OUTPUT_DIR]`` (default ``out/``); needs the
``report`` extra (``pip install ".[report]"``). Writes:

- ``OUTPUT_DIR/report/``: the analysis folder of the flying shears (``index.html`` first), the
  same as ``linkage report flying_shears --out OUTPUT_DIR/report``;
- ``OUTPUT_DIR/assignments/``: four variants of the shaper template with their sheets and answer
  keys, the same as ``linkage variants shaper_two_dyad --count 4 --seed 3 --out ...``.
"""

import sys
from pathlib import Path

import linkage
from linkage.report.folder import ReportExtraMissing, require_report_extra

try:
    require_report_extra("this example")
except ReportExtraMissing as exc:
    print(exc)
    sys.exit(0)

from linkage.report.folder import write_report  # noqa: E402
from linkage.course.template import load_template  # noqa: E402
from linkage.course.variants import select_variants, write_variants  # noqa: E402

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")

report = write_report(linkage.load("flying_shears"), out / "report")
print(f"{report.folder / 'index.html'}: {len(report.pictures)} pictures")
for note in report.notes:
    print("  note:", note)

selection = select_variants(load_template("shaper_two_dyad"), count=4, seed=3)
print("\n".join(selection.lines()))
for folder in write_variants(selection, out / "assignments", workers=2):
    print(folder / "sheet.pdf", folder / "key.json")
