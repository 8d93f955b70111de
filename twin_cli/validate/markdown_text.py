"""Report text as Markdown that renders as written, on GitHub and any CommonMark page.

Check results carry plain text: `|α − I⁻¹τ|` in a measured value splits a Markdown table's cell
at each `|`, and a tag such as `<limit effort>` in a hint is read as HTML and dropped. Tags become
code spans; in a table cell every `|` is escaped (inside a code span too, as GitHub's tables
require).
"""

from __future__ import annotations

import re

_CODE = re.compile(r"(`[^`]*`)")
_TAG = re.compile(r"</?[A-Za-z][^<>]*>")


def inline(text: str) -> str:
    """`text` with each tag outside a code span turned into a code span."""
    parts = _CODE.split(text)
    return "".join(
        part if part.startswith("`") else _TAG.sub(lambda m: f"`{m.group(0)}`", part)
        for part in parts
    )


def cell(text: str) -> str:
    """`text` for one table cell: `inline`, every `|` escaped, on one line."""
    return inline(" ".join(str(text).split())).replace("|", "\\|")
