"""A ROS message (as JSON values) in the YAML-like text `ros2 topic echo` prints.

Nested messages indent by two spaces; sequences of numbers or strings are one `- item` per line
at the key's indentation, sequences of messages `- field: ...` blocks; an empty string is `''`
and an empty sequence `[]`. A non-finite float prints as YAML spells it, as `ros2 topic echo`
does: `.inf`, `-.inf`, `.nan` (a lidar's ray with no return is `.inf`). JSON has no such numbers:
`json_safe` makes them null for `--json`. Pure Python: the client imports no numpy.
"""

from __future__ import annotations

import math
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


def json_safe(value: Any) -> Any:
    """`value` with every non-finite float replaced by None (JSON's null), for strict JSON."""
    if isinstance(value, dict):
        return {key: json_safe(item) for key, item in value.items()}
    if isinstance(value, list):
        return [json_safe(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _scalar(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, float) and not math.isfinite(value):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf")
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        plain = value and value == value.strip() and "\n" not in value and value != "..."
        return value if plain else repr(value)
    return str(value)
