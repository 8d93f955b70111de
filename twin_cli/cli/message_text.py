"""A ROS message (as JSON values) in the YAML-like text `ros2 topic echo` prints.

Nested messages indent by two spaces; sequences of numbers or strings are one `- item` per line
at the key's indentation, sequences of messages `- field: ...` blocks; an empty string is `''`
and an empty sequence `[]`. A non-finite float, which JSON cannot carry, arrives as None and
prints as `null`. Pure Python: the client imports no numpy.
"""

from __future__ import annotations

from typing import Any


def message_text(message: dict[str, Any]) -> str:
    """The lines of `message` (no trailing `---`; the caller separates messages)."""
    return "\n".join(_fields(message, 0))


def _fields(message: dict[str, Any], depth: int) -> list[str]:
    pad, out = "  " * depth, []
    for key, value in message.items():
        if isinstance(value, dict):
            out.append(f"{pad}{key}:")
            out += _fields(value, depth + 1)
        elif isinstance(value, list):
            out += [f"{pad}{key}: []"] if not value else [f"{pad}{key}:", *_items(value, depth)]
        else:
            out.append(f"{pad}{key}: {_scalar(value)}")
    return out


def _items(values: list[Any], depth: int) -> list[str]:
    pad, out = "  " * depth, []
    for value in values:
        if isinstance(value, dict):
            block = _fields(value, depth + 1)
            out.append(f"{pad}- {block[0].lstrip()}" if block else f"{pad}- {{}}")
            out += block[1:]
        else:
            out.append(f"{pad}- {_scalar(value)}")
    return out


def _scalar(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        plain = value and value == value.strip() and "\n" not in value and value != "..."
        return value if plain else repr(value)
    return str(value)
