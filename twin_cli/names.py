"""One rule for entity names, checked the same way by the CLI, the HTTP API and the world.

A name prefixes every element of its entity in the world's MjSpec ("<name>/link"), names one
URL path segment, and is typed in shells: 1-200 characters, no '/', no whitespace or control
characters. Standard library only: client commands check a name before any request.
"""

from __future__ import annotations

MAX_LENGTH = 200
RULE = "1-200 characters without '/', spaces or control characters"
EXAMPLE = "robot_1"


def name_problem(name: str) -> str | None:
    """What is wrong with `name` as an entity name, or None when it is fine."""
    if not isinstance(name, str) or not name:
        return "is empty"
    if len(name) > MAX_LENGTH:
        return f"is {len(name)} characters long"
    if "/" in name:
        return "contains '/', which separates an entity from its links and joints"
    if any(c.isspace() or not c.isprintable() for c in name):
        return "contains a space or a control character"
    return None


def name_message(name: str) -> str:
    """The one message for a bad name: what is wrong, the rule and an example."""
    shown = name if len(name) <= 60 else name[:57] + "..."
    return f"entity name [{shown}] {name_problem(name)}; use {RULE}, e.g. {EXAMPLE}"
