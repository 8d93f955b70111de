"""Which description format a text is, from its root element: URDF, SDF or MJCF."""

from __future__ import annotations

import re

# Leading byte-order mark (a UTF-8 file read as text keeps it as U+FEFF; XML parsers skip it),
# XML declaration, processing instructions, comments and doctype before the root.
_PROLOGUE = re.compile(r"\A\ufeff?(?:\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)*", re.S)
_ROOT = re.compile(r"<([A-Za-z_][\w.\-]*:)?([A-Za-z_][\w.\-]*)")

# Root element → format name.
FORMATS = {"robot": "urdf", "sdf": "sdf", "mujoco": "mjcf"}


def root_tag(text: str) -> str | None:
    """The root element's local name, or None when the text does not start with an element."""
    prologue = _PROLOGUE.match(text)  # always matches (all of it may be empty)
    rest = text[prologue.end() :] if prologue else text
    found = _ROOT.match(rest)
    return found.group(2) if found else None


def format_of(text: str) -> str | None:
    """ "urdf", "sdf" or "mjcf" by the root element (xacro files are URDF), else None."""
    return FORMATS.get(root_tag(text) or "")
