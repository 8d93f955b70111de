"""Comments and docstrings stand on the repository alone: no pointer to a document outside it, to
a tracker number or to a planning round, which a reader of the code cannot follow."""

from __future__ import annotations

import fnmatch
import io
import re
import tokenize
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("converters", "twin_cli", "scenarios", "tests", "benchmarks", "scripts")
NOT_YET_CHECKED: tuple[str, ...] = ()
"""Files whose comments are not scanned yet (none: every file is)."""

POINTERS = {
    "a section of a document": re.compile(r"§"),
    "a tracker number": re.compile(r"\bissues? #?\d+|#\d+\b|\(#\d+\)", re.IGNORECASE),
    "a planning round": re.compile(r"\b(stop|wave|milestone) \d+\b", re.IGNORECASE),
    "the brief": re.compile(r"\bthe brief\b", re.IGNORECASE),
    "a document beside the repository": re.compile(r"\.\./shared/(?!corpus\b)"),
}
MARKDOWN = re.compile(r"[\w./-]*[\w-]\.md\b")
OPENERS = {"(", "[", "{"}
CLOSERS = {")", "]", "}"}
STATEMENT_START = {tokenize.NEWLINE, tokenize.NL, tokenize.INDENT, tokenize.DEDENT}


def _scanned_files() -> list[Path]:
    files = [p for top in SCANNED for p in sorted((ROOT / top).rglob("*.py"))]
    return [p for p in files if not _not_yet_checked(p.relative_to(ROOT))]


def _not_yet_checked(relative: Path) -> bool:
    return any(fnmatch.fnmatch(relative.as_posix(), pattern) for pattern in NOT_YET_CHECKED)


def _prose(source: str) -> Iterator[tuple[int, str]]:
    """(line, text) of every comment and every docstring: a string that is a statement of its
    own (module, class and function docstrings, and the ones under an attribute)."""
    depth, previous = 0, tokenize.NEWLINE
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            yield token.start[0], token.string
            continue
        if token.type == tokenize.STRING and depth == 0 and previous in STATEMENT_START:
            yield from _lines(token.start[0], token.string)
        if token.type == tokenize.OP:
            depth += (token.string in OPENERS) - (token.string in CLOSERS)
        previous = token.type


def _lines(first: int, text: str) -> Iterator[tuple[int, str]]:
    for offset, line in enumerate(text.splitlines()):
        yield first + offset, line


def _problems(line: str) -> list[str]:
    found = [what for what, pattern in POINTERS.items() if pattern.search(line)]
    outside = [m for m in MARKDOWN.findall(line) if not _in_repository(m)]
    return found + [f"{name}, a document outside the repository" for name in outside]


def _in_repository(markdown: str) -> bool:
    """A Markdown file the repository holds: at its root, under docs/, or at the given path."""
    name = Path(markdown).name
    return any(p.is_file() for p in (ROOT / markdown, ROOT / name, ROOT / "docs" / name))


def test_the_scan_finds_each_kind_of_pointer() -> None:
    source = (
        '"""Why, see design.md §2."""\n'
        "x = 1  # the limit of issue 3\n"
        "y = 2  # measured at stop 23\n"
        "z = f('a', '''wave 2''')  # an argument, not a docstring\n"
    )
    found = {line: _problems(text) for line, text in _prose(source) if _problems(text)}
    assert sorted(found) == [1, 2, 3]
    assert "design.md, a document outside the repository" in found[1]


def test_paths_to_data_and_documents_in_the_repository_pass() -> None:
    assert not _problems("# the corpus at ../shared/corpus; see docs/scenarios.md and README.md")


def test_every_comment_and_docstring_stands_on_the_repository_alone() -> None:
    offenders = []
    for path in _scanned_files():
        for line, text in _prose(path.read_text(encoding="utf-8")):
            for problem in _problems(text):
                offenders.append(f"{path.relative_to(ROOT)}:{line}: {problem}: {text.strip()}")
    assert not offenders, "\n".join(offenders)
