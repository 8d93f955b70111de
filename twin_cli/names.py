"""One rule for entity names, checked the same way by the CLI, the HTTP API and the world.

A name prefixes every element of its entity in the world's MjSpec ("<name>/link"), names one
URL path segment (percent-encoded), and is typed in shells (quoted when it has a space): 1-200
characters, no '/', no control characters, no space at either end. Spaces inside and any
Unicode letter are kept as libsdformat keeps them (gz-sim's own `Heightmap Bowl`). Standard
library only: client commands check a name before any request.
"""

from __future__ import annotations

MAX_LENGTH = 200
RULE = "1-200 characters without '/', control characters or a space at either end"
EXAMPLE = "robot_1"


def name_problem(name: str) -> str | None:
    """What is wrong with `name` as an entity name, or None when it is fine."""
    if not isinstance(name, str) or not name:
        return "is empty"
    if len(name) > MAX_LENGTH:
        return f"is {len(name)} characters long"
    if "/" in name:
        return "contains '/', which separates an entity from its links and joints"
    if any(not (c.isprintable() or c == " ") for c in name):
        return "contains a control character (a tab, a line break)"
    if name != name.strip():
        return "begins or ends with a space"
    return None


def name_message(name: str) -> str:
    """The one message for a bad name: what is wrong, the rule and an example."""
    shown = name if len(name) <= 60 else name[:57] + "..."
    return f"entity name [{shown}] {name_problem(name)}; use {RULE}, e.g. {EXAMPLE}"


def as_entity_name(name: str) -> str:
    """A model's own name as an entity name: kept as given when it is one (spaces and Unicode
    too), else each '/' or control character made '_', the ends stripped, cut to the limit."""
    if name_problem(name) is None:
        return name
    mapped = "".join("_" if c == "/" or not (c.isprintable() or c == " ") else c for c in name)
    return mapped.strip()[:MAX_LENGTH].strip() or "model"


def topic_segment(name: str) -> str:
    """An entity name as one segment of a ROS topic name (`/<segment>/joint_states`).

    ROS 2 allows ASCII letters, digits and '_' in a segment, not a leading digit; gz-transport's
    `AsValidTopic` turns a space into '_'. Accents are dropped (`Ü` → `U`), any other character
    becomes '_', and a leading digit gets a '_' before it: `Heightmap Bowl` → `Heightmap_Bowl`.
    """
    import unicodedata

    decomposed = unicodedata.normalize("NFKD", name)
    plain = "".join(c for c in decomposed if not unicodedata.combining(c))
    segment = "".join(c if c.isascii() and (c.isalnum() or c == "_") else "_" for c in plain)
    segment = segment or "_"
    return f"_{segment}" if segment[0].isdigit() else segment


def namespace(entity: str) -> str:
    """An entity's ROS namespace: `/` and its name as one topic segment (`topic_segment`), so a
    model named `Heightmap Bowl` publishes `/Heightmap_Bowl/joint_states`."""
    return f"/{topic_segment(entity)}"
