"""The `--markdown` report renders as written: a CommonMark renderer with GitHub's tables (the
markdown-it-py that rich installs) reads every table row with its four cells, shows the
inertia check's `|α − I⁻¹τ|` in its cell, and keeps the `<limit effort>` a hint names as text,
not as HTML it would drop."""

from __future__ import annotations

import pytest
from markdown_it import MarkdownIt
from models import CONTROL_RIG, write_urdf

from twin_cli.validate import validate
from twin_cli.validate.report import markdown


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> str:
    # The rig's slider with 0.05 N of effort cannot follow the sine: its hint names the tag.
    weak = CONTROL_RIG.replace('effort="50"', 'effort="0.05"')
    robot = write_urdf(tmp_path_factory.mktemp("md"), weak, "rig.urdf")
    return markdown(validate(robot, only=["inertia", "tracking", "inertial"]))


def _rows(text: str) -> list[list[str]]:
    """Each table row's cells as the renderer reads them."""
    tokens = MarkdownIt("commonmark").enable("table").parse(text)
    rows, row = [], None
    for i, token in enumerate(tokens):
        if token.type == "tr_open":
            row = []
        elif token.type in ("th_open", "td_open"):
            row.append(tokens[i + 1].content if tokens[i + 1].type == "inline" else "")
        elif token.type == "tr_close":
            rows.append(row)
    return rows


def _texts(text: str) -> list[str]:
    """The plain text a reader sees: inline tokens' text and code spans, no HTML."""
    tokens = MarkdownIt("commonmark").enable("table").parse(text)
    out = []
    for token in tokens:
        assert token.type not in ("html_block", "html_inline"), token
        for child in token.children or []:
            assert child.type != "html_inline", f"read as HTML: {child.content!r}"
            if child.type in ("text", "code_inline"):
                out.append(child.content)
    return out


def test_every_table_row_keeps_its_four_cells(page: str) -> None:
    rows = _rows(page)
    assert len(rows) == 4, rows  # the header and three checks
    assert all(len(row) == 4 for row in rows), rows
    inertia = next(row for row in rows if row[1] == "inertia")
    assert inertia[2].startswith("|α − I⁻¹τ| / |I⁻¹τ| = "), inertia  # whole, bars and all


def test_a_hints_tag_is_shown_as_code_not_dropped_as_html(page: str) -> None:
    shown = _texts(page)
    assert "<limit effort>" in shown, [t for t in shown if "limit" in t]
