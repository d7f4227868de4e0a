"""The package's layout: no import cycle, and no stage imports a later one.

The stages, in the order data flows (``docs/README.md``, "How it is built"): the group solvers
(``assur``), errors, the model, the structure, kinematics, kinetostatics, dynamics, the report,
then course and research (side by side: neither imports the other), the command line, and the
package's public face. Imports are read with :mod:`ast` (inside functions too), so the test needs
nothing but the source.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: stage -> rank; a module belongs to the longest stage name that prefixes it
STAGES = {
    "assur": 0,
    "linkage.errors": 1,
    "linkage.version": 1,
    "linkage.workers": 2,
    "linkage.model": 2,
    "linkage.structure": 3,
    "linkage.kinematics": 4,
    "linkage.kinetostatics": 5,
    "linkage.dynamics": 6,
    "linkage.report": 7,
    "linkage.course": 8,
    "linkage.research": 8,
    "linkage.cli": 9,
    "linkage": 10,
}
#: the largest number of lines a module may have (about 800)
MAX_LINES = 820


def _modules() -> dict[str, Path]:
    found = {}
    for package in ("linkage", "assur"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            found[name] = path
    return found


MODULES = _modules()


def stage(module: str) -> str:
    """The stage a module belongs to (the longest stage name that prefixes it)."""
    return max((s for s in STAGES if module == s or module.startswith(s + ".")), key=len)


def _absolute(module: str, path: Path, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    base = package[: len(package) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def imports(module: str, path: Path) -> set[str]:
    """The project's modules ``module`` imports (anywhere in its source): a name imported from a
    package counts as the submodule when it is one, else as the package."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(module, path, node)
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
        else:
            continue
        found.update(t for t in targets if t in MODULES and t != module)
    return found


GRAPH = {module: imports(module, path) for module, path in MODULES.items()}


def test_stages_are_known():
    assert set(GRAPH) >= {"linkage.model", "linkage.kinematics", "linkage.kinetostatics", "linkage.dynamics",
                          "linkage.course", "linkage.research", "linkage.report", "linkage.cli"}
    # every module of the project has a stage
    assert all(stage(m) in STAGES for m in GRAPH)


def test_no_stage_imports_a_later_one():
    wrong = []
    for module, targets in GRAPH.items():
        for target in targets:
            a, b = stage(module), stage(target)
            if STAGES[b] > STAGES[a] or (STAGES[b] == STAGES[a] and a != b):
                wrong.append(f"{module} ({a}) imports {target} ({b})")
    assert not wrong, "\n".join(wrong)


def test_no_import_cycle():
    state: dict[str, int] = {}          # 1: on the path, 2: done
    path: list[str] = []
    cycles = []

    def visit(module: str) -> None:
        state[module] = 1
        path.append(module)
        for target in sorted(GRAPH[module]):
            if state.get(target) == 1:
                cycles.append(" -> ".join(path[path.index(target):] + [target]))
            elif target not in state:
                visit(target)
        path.pop()
        state[module] = 2

    for module in sorted(GRAPH):
        if module not in state:
            visit(module)
    assert not cycles, "\n".join(cycles)


@pytest.mark.parametrize("source, target", [("linkage.kinematics.motion", "linkage.dynamics.pipeline"),
                                            ("linkage.course.variants", "linkage.research.enumeration")])
def test_the_rule_refuses_what_it_should(source, target):
    """The rule itself: a lower stage importing a higher one, or a sibling importing a sibling."""
    a, b = stage(source), stage(target)
    assert STAGES[b] > STAGES[a] or (STAGES[b] == STAGES[a] and a != b)


def test_the_cycle_finder_finds_a_cycle(monkeypatch):
    monkeypatch.setitem(GRAPH, "linkage.errors", GRAPH["linkage.errors"] | {"linkage.model.mechanism"})
    with pytest.raises(AssertionError, match="linkage.errors -> linkage.model"):
        test_no_import_cycle()


def test_no_module_too_long():
    long = {m: n for m, p in MODULES.items() if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_every_package_says_what_it_holds():
    for module, path in MODULES.items():
        if path.name == "__init__.py":
            doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
            assert doc and len(doc) > 80, f"{module}: its __init__.py has no paragraph saying what it holds"
