"""The README and the documentation say what the repository does.

1. ``.ci/run`` runs the README's test command, word for word. The rule: the README's quick start
   has one command line with ``pytest`` in it; split at ``&&`` into commands (shell words, quotes
   removed: ``".[test]"`` is the word ``.[test]``), each command must be run by ``.ci/run`` with
   exactly the same words, in the same order, one after the other, under ``set -e`` (a failed
   install stops the run). The only difference allowed is a leading ``python3 -m`` (or
   ``python -m``): it runs the same module (pip, pytest) of the interpreter CI uses, without
   depending on where that interpreter's scripts lie on PATH. No option may be added or left
   out (``--quiet`` is a different command line). For pytest that prefix also puts the working
   directory on ``sys.path``, which once hid a collection failure that a plain ``pytest`` on a
   fresh clone met (issue 8); the root ``conftest.py`` makes the two import the same source tree,
   so the prefix is accepted only while it is there.
2. Every file the README and the documentation cite exists: backticked paths under a top-level
   folder of the repository (``docs/methods.md``, ``benchmarks/RESULTS.md``, ``assur/rrr.py``),
   the same in code blocks, and the targets (and ``#anchors``) of relative Markdown links.
3. Nothing the project carries cites a document that is not in it (``METHOD``, ``DESIGN``,
   ``STYLE``): not the README, the docs, the scheme format, the ``--help`` texts, nor the
   docstrings and comments of the packages and shipped schemes.
4. The examples run as written: the README's Python blocks and its ``linkage`` command lines, and
   the ``>>>`` examples of ``docs/*.md`` with their outputs.
"""

from __future__ import annotations

import argparse
import contextlib
import doctest
import io
import os
import re
import shlex
import unicodedata
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
CI_RUN = ROOT / ".ci" / "run"
DOCS = sorted((ROOT / "docs").glob("*.md"))
#: the documentation the project carries (the README, docs/, the scheme format)
DOCUMENTS = [README, *DOCS, ROOT / "schemes" / "README.md"]
#: top-level folders whose files the documents may cite (a path under another name is not a file
#: of the repository: ``out/``, the examples' output folder)
FOLDERS = ("docs", "benchmarks", "schemes", "examples", "linkage", "assur", "tests", ".ci")
#: folders whose source (docstrings, comments, help text) must not cite documents outside the repo
SOURCES = ("linkage", "assur", "schemes")
#: interpreter prefixes .ci/run may put before a command of the README
PREFIXES = (("python3", "-m"), ("python", "-m"))
#: documents that are not in the repository
FOREIGN = re.compile(r"\b(METHOD|DESIGN|STYLE)\b")


def _text(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


# ----------------------------------------------------------------------------------------------
# 1. the README's test command and .ci/run
# ----------------------------------------------------------------------------------------------


def _commands(line: str) -> list[list[str]]:
    """Shell words of ``line`` (quotes removed, ``#`` comments dropped), split into commands at
    ``&&`` and ``;``."""
    lexer = shlex.shlex(line, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    commands: list[list[str]] = [[]]
    for word in lexer:
        if word in ("&&", ";"):
            commands.append([])
        else:
            commands[-1].append(word)
    return [c for c in commands if c]


def _fenced_blocks(text: str) -> list[tuple[str, str]]:
    """``(language, body)`` of every fenced code block."""
    return [(m.group(1).strip(), m.group(2)) for m in re.finditer(r"^```([^\n]*)\n(.*?)^```", text, re.M | re.S)]


def _quick_start_lines() -> list[str]:
    section = _text(README).split("## Quick start", 1)[1].split("\n## ", 1)[0]
    blocks = [body for lang, body in _fenced_blocks(section) if lang in ("sh", "bash", "console", "")]
    assert blocks, "the README's quick start has no shell block"
    return [line for line in blocks[0].splitlines() if line.strip()]


def readme_test_command() -> list[list[str]]:
    lines = [line for line in _quick_start_lines() if "pytest" in _commands(line)[-1]]
    assert len(lines) == 1, f"the quick start should have one test command line, found {lines}"
    return _commands(lines[0])


def ci_commands() -> tuple[list[list[str]], list[str]]:
    """The commands ``.ci/run`` runs (``cd`` and ``set`` aside) and its ``set`` lines."""
    commands, settings = [], []
    for line in _text(CI_RUN).splitlines():
        for words in _commands(line):
            if words[0] == "set":
                settings.append(" ".join(words))
            elif words[0] != "cd":
                commands.append(words)
    return commands, settings


def _unprefixed(words: list[str]) -> list[str]:
    for prefix in PREFIXES:
        if tuple(words[: len(prefix)]) == prefix:
            return words[len(prefix):]
    return words


def test_readme_quick_start_has_the_two_commands():
    """Install and run; install the test tools and run the tests."""
    lines = _quick_start_lines()
    assert len(lines) == 2, lines
    first, second = (_commands(line) for line in lines)
    assert first[0][:2] == ["pip", "install"] and first[-1][0] == "linkage", lines[0]
    assert second[0][:2] == ["pip", "install"] and second[-1] == ["pytest"], lines[1]


def test_ci_runs_the_readme_test_command_word_for_word():
    wanted = readme_test_command()
    commands, settings = ci_commands()
    run = [_unprefixed(c) for c in commands]
    starts = [i for i in range(len(run) - len(wanted) + 1) if run[i:i + len(wanted)] == wanted]
    shown = "\n".join("  " + shlex.join(c) for c in commands)
    assert starts, (f".ci/run must run the README's test command {' && '.join(shlex.join(c) for c in wanted)!r} "
                    f"word for word (a 'python3 -m' prefix allowed), but it runs:\n{shown}")
    assert any(re.fullmatch(r"set( -\w+)* -\w*e\w*( .*)?", s) for s in settings), \
        f".ci/run must stop at the first failing command (set -e), has {settings}"
    assert os.access(CI_RUN, os.X_OK), ".ci/run must be executable"
    i = starts[0]
    prefixed_pytest = any(c[-1] == "pytest" and c != w for c, w in zip(commands[i:], wanted))
    if prefixed_pytest:
        assert (ROOT / "conftest.py").is_file(), (
            "'python3 -m pytest' in .ci/run puts the checkout on sys.path, which a plain 'pytest' (the "
            "README's command) does only with the root conftest.py: keep it, or run plain 'pytest'")


def test_the_rule_refuses_what_is_not_the_same_command():
    """The comparison itself: quotes do not matter, an added option or another module does."""
    assert _commands('pip install ".[test]" && pytest') == [["pip", "install", ".[test]"], ["pytest"]]
    assert _unprefixed(_commands("python3 -m pip install '.[test]'")[0]) == ["pip", "install", ".[test]"]
    assert _unprefixed(_commands('python3 -m pip install --quiet ".[test]"')[0]) != ["pip", "install", ".[test]"]
    assert _unprefixed(_commands("python3 -m pytest -x")[0]) != ["pytest"]
    assert _unprefixed(_commands("python3 pytest")[0]) != ["pytest"]


# ----------------------------------------------------------------------------------------------
# 2. cited files exist
# ----------------------------------------------------------------------------------------------

_PATH = re.compile(r"^(?:\./)?(?:%s)/[\w.*\-/]*$" % "|".join(re.escape(f) for f in FOLDERS))


def _cited_paths(text: str) -> set[str]:
    """Paths under the repository's top-level folders, backticked or as words of code blocks."""
    found = set(re.findall(r"`([^`\s]+)`", text))
    for _, body in _fenced_blocks(text):
        found |= set(re.findall(r"[^\s`'\"()\[\],;]+", body))
    return {p.rstrip(".,:;") for p in found if _PATH.match(p.rstrip(".,:;"))}


def _exists(path: str) -> bool:
    if "*" in path:
        return any(ROOT.glob(path.removeprefix("./")))
    return (ROOT / path).exists()


def _slug(heading: str) -> str:
    """The anchor GitHub gives a heading."""
    text = re.sub(r"[`*_]", lambda m: "_" if m.group() == "_" else "", heading.strip().lower())
    kept = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return kept.replace(" ", "-")


def _anchors(path: Path) -> set[str]:
    text = re.sub(r"^```.*?^```", "", _text(path), flags=re.M | re.S)
    return {_slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.+?)\s*#*$", text, re.M)}


@pytest.mark.parametrize("doc", DOCUMENTS, ids=_rel)
def test_cited_paths_exist(doc):
    missing = sorted(p for p in _cited_paths(_text(doc)) if not _exists(p))
    assert not missing, f"{_rel(doc)} cites files that are not in the repository: {missing}"


@pytest.mark.parametrize("doc", DOCUMENTS, ids=_rel)
def test_relative_links_resolve(doc):
    text = re.sub(r"^```.*?^```", "", _text(doc), flags=re.M | re.S)
    broken = []
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue  # https:, mailto:
        file, _, anchor = target.partition("#")
        path = (doc.parent / file).resolve() if file else doc
        if not path.exists() or ROOT not in path.parents:
            broken.append(target)
        elif anchor and path.suffix == ".md" and anchor not in _anchors(path):
            broken.append(target)
    assert not broken, f"{_rel(doc)}: links to missing files or headings: {broken}"


def test_the_path_finder_finds_paths():
    text = "see `docs/methods.md`, `out/` and `B.x`\n```\nlinkage/cli.py   the command line\n```\n"
    assert _cited_paths(text) == {"docs/methods.md", "linkage/cli.py"}
    assert _slug("Coefficient of dynamics") == "coefficient-of-dynamics"
    assert _slug("Mertsalov's method (the course method)") == "mertsalovs-method-the-course-method"


def test_docs_index_lists_every_page():
    index = _text(ROOT / "docs" / "README.md")
    for page in DOCS:
        if page.name != "README.md":
            assert f"({page.name})" in index, f"docs/README.md does not list {page.name}"


# ----------------------------------------------------------------------------------------------
# 3. no citation of documents outside the repository
# ----------------------------------------------------------------------------------------------


def _foreign(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines() if FOREIGN.search(line)]


@pytest.mark.parametrize("doc", DOCUMENTS, ids=_rel)
def test_documents_cite_only_the_repository(doc):
    assert not _foreign(_text(doc)), f"{_rel(doc)} cites documents that are not in the repository"


def _help_texts() -> dict[str, str]:
    from linkage.cli import build_parser

    parser = build_parser()
    texts = {"linkage --help": parser.format_help()}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):  # the subcommands' parsers
            for name, sub in action.choices.items():
                texts[f"linkage {name} --help"] = sub.format_help()
    assert len(texts) > 1, "no subcommands found"
    return texts


def test_help_cites_only_the_repository():
    bad = {name: _foreign(text) for name, text in _help_texts().items() if _foreign(text)}
    assert not bad, f"help texts cite documents that are not in the repository: {bad}"


def test_help_cites_existing_docs():
    for name, text in _help_texts().items():
        for path in re.findall(r"\b(?:docs|schemes)/[\w\-]+\.md\b", " ".join(text.split())):
            assert (ROOT / path).is_file(), f"{name} cites {path}, which does not exist"


def test_sources_cite_only_the_repository():
    hits = []
    for folder in SOURCES:
        for path in sorted((ROOT / folder).rglob("*")):
            if path.suffix in (".py", ".toml", ".md") and "__pycache__" not in path.parts:
                hits += [f"{_rel(path)}: {line}" for line in _foreign(_text(path))]
    assert not hits, "cited documents that are not in the repository:\n" + "\n".join(hits)


# ----------------------------------------------------------------------------------------------
# 4. the examples run as written
# ----------------------------------------------------------------------------------------------


def _readme_blocks(language: str) -> list[str]:
    return [body for lang, body in _fenced_blocks(_text(README)) if lang == language]


@pytest.mark.parametrize("index", range(len(_readme_blocks("python"))))
def test_readme_python_blocks_run(index, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing written into the checkout
    code = _readme_blocks("python")[index]
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("error")   # the examples run as written, without a warning a reader would meet
        exec(compile(code, f"README.md python block {index + 1}", "exec"), {"__name__": "__readme__"})


def _readme_linkage_commands() -> list[str]:
    """Every ``linkage ...`` command of the README's shell blocks (the quick start's included),
    once each."""
    found = []
    for lang, body in _fenced_blocks(_text(README)):
        if lang in ("sh", "bash"):
            for line in body.splitlines():
                found += [shlex.join(c) for c in _commands(line) if c[0] == "linkage"]
    return list(dict.fromkeys(found))


@pytest.mark.parametrize("command", _readme_linkage_commands())
def test_readme_command_lines_run(command, linkage_run):
    """Each command as written, in a folder of its own (tests that check its output more closely
    share the same run: ``linkage_run`` in tests/conftest.py)."""
    done = linkage_run(*shlex.split(command)[1:])
    assert done.status == 0, f"{command} -> exit {done.status}\n{done.err[-2000:]}"
    assert done.out.strip(), f"{command} printed nothing"


@pytest.mark.parametrize("doc", DOCS, ids=_rel)
def test_docs_examples_run(doc, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # a warning fails its example (doctest reports it)
        result = doctest.testfile(str(doc), module_relative=False, encoding="utf-8", report=True,
                                  optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples of {_rel(doc)} fail (see above)"
