"""An SDFormat document: parsed with line numbers, version checked, typed values read from it.

Every value read goes through `SdfContext`, so a bad number or a missing element becomes an
`SDFError` naming `file:line`, the element and the fix, never a Python exception.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from converters.description.transforms import pose_matrix, quat_matrix
from converters.errors import MalformedXMLError, SDFError
from converters.gazebo.tags import ValueContext
from converters.report import Report
from converters.resources.packages import PackageResolver

# SDFormat versions twin reads: 1.4 (Gazebo 2) to 1.11 (Gazebo Ionic).
VERSIONS = ("1.4", "1.5", "1.6", "1.7", "1.8", "1.9", "1.10", "1.11")
# Pose frame semantics (`relative_to`, `<frame attached_to>`) start at 1.7; sdformat reads an
# older file by upgrading it, so `relative_to` and `expressed_in` count in every version.
FRAME_SEMANTICS_FROM = (1, 7)
# Attributes set on an element an `<include>` brought in: its file and that file's version.
INCLUDED_SOURCE = "_twin_source"
INCLUDED_VERSION = "_twin_version"


def version_tuple(version: str) -> tuple[int, int]:
    major, _, minor = version.partition(".")
    return int(major), int(minor or 0)


@dataclass
class SdfContext:
    """What reading one file needs: its name, directory, package resolver, report, version."""

    source: str
    base_dir: Path
    resolver: PackageResolver
    report: Report = field(default_factory=Report)
    version: str = "1.11"

    def version_of(self, element: Any) -> str:
        """The SDFormat version of the file `element` was written in (an include's own)."""
        for ancestor in (element, *element.iterancestors()):
            marked = ancestor.get(INCLUDED_VERSION)
            if marked:
                return marked
        return self.version

    def before_frames(self, element: Any) -> bool:
        """True when `element`'s file predates pose frame semantics (SDFormat 1.4-1.6)."""
        return version_tuple(self.version_of(element)) < FRAME_SEMANTICS_FROM

    def error(self, element: Any, problem: str, fix: str) -> SDFError:
        """An SDFError at `element` (in the file an `<include>` brought it from, if any)."""
        return SDFError(
            source_of(element, self.source), line_of(element), describe(element), problem, fix
        )

    def values(self, element: Any) -> ValueContext:
        """A value context whose failures name this file, line and element."""
        return _SdfValues(self, element)

    def text(self, parent: Any, tag: str, default: str | None = None) -> str | None:
        child = parent.find(tag)
        if child is None or child.text is None:
            return default
        return child.text.strip()

    def number(self, parent: Any, tag: str, default: float) -> float:
        """A finite number from child `tag` of `parent`, `default` when the child is absent."""
        raw = self.text(parent, tag)
        return default if raw is None else self.parse_number(parent.find(tag), raw)

    def parse_number(self, element: Any, raw: str) -> float:
        try:
            value = float(raw)
        except ValueError as exc:
            raise self.error(element, f"{raw!r} is not a number", "write a decimal number") from exc
        if not math.isfinite(value):
            raise self.error(element, f"{raw!r} is not finite", "write a finite number")
        return value

    def vector(self, parent: Any, tag: str, size: int, default: tuple[float, ...]) -> tuple:
        """`size` numbers from child `tag` (space-separated), `default` when absent."""
        raw = self.text(parent, tag)
        if raw is None:
            return default
        element = parent.find(tag)
        parts = raw.split()
        if len(parts) != size:
            raise self.error(element, f"{raw!r} has {len(parts)} numbers", f"write {size} numbers")
        return tuple(self.parse_number(element, p) for p in parts)

    def flag(self, parent: Any, tag: str, default: bool) -> bool:
        raw = self.text(parent, tag)
        if raw is None:
            return default
        word = raw.lower()
        if word in ("true", "1"):
            return True
        if word in ("false", "0"):
            return False
        raise self.error(parent.find(tag), f"{raw!r} is not a boolean", "write true or false")

    def flag_attribute(self, element: Any, name: str) -> bool:
        """A boolean attribute (`merge="true"`), false when absent."""
        raw = (element.get(name) or "false").strip().lower()
        if raw in ("true", "1", "false", "0"):
            return raw in ("true", "1")
        raise self.error(element, f"{name}={raw!r} is not a boolean", f"write {name}='true'")


class _SdfValues(ValueContext):
    """Gazebo's value readers (shared with URDF `<gazebo>` tags), failing as SDF errors."""

    def __init__(self, ctx: SdfContext, element: Any) -> None:
        super().__init__(ctx.source, describe(element))
        self.ctx = ctx
        self.element = element

    def fail(self, tag: str, value: str, expected: str) -> SDFError:
        found = self.element.find(tag)
        at = found if found is not None else self.element
        return self.ctx.error(at, f"<{tag}> {value!r} is not {expected}", f"write {expected}")


def source_of(element: Any, default: str) -> str:
    for ancestor in (element, *element.iterancestors()):
        marked = ancestor.get(INCLUDED_SOURCE)
        if marked:
            return marked
    return default


def line_of(element: Any) -> int | None:
    return getattr(element, "sourceline", None)


def describe(element: Any) -> str:
    """`<tag name='x'>` for messages."""
    name = element.get("name")
    return f"<{element.tag} name='{name}'>" if name else f"<{element.tag}>"


_COMMENT = re.compile(r"<!--(.*?)-->", re.DOTALL)
_DECLARATION = re.compile(r"<\?xml\b[^>]*\?>")


def _as_tinyxml_reads(text: str) -> str:
    """`text` with what tinyxml2 (sdformat's parser) tolerates made well-formed: comments that
    contain `--` (gz-sim's own `empty.sdf` quotes a `gz service --reqtype ...` command in one)
    and an XML declaration after a leading comment (gazebo-classic's `cafe.world`). Comments
    keep their line breaks, so error positions stay on their lines."""
    text = _COMMENT.sub(lambda m: "<!--" + "\n" * m.group(1).count("\n") + "-->", text)
    stripped = text.lstrip()  # tinyxml2 also takes blank lines before the declaration
    if stripped.startswith("<?xml") and "?>" in stripped:  # the one declaration allowed
        end = stripped.index("?>") + 2
        lead = "\n" * text[: len(text) - len(stripped)].count("\n")  # kept after it: lines
        return stripped[:end] + lead + _DECLARATION.sub(_blank, stripped[end:])
    return _DECLARATION.sub(_blank, text)


def _blank(match: re.Match) -> str:
    """A removed span's line breaks, so the lines after it keep their numbers."""
    return "\n" * match.group(0).count("\n")


def _check_well_formed(text: str, source: str, first: Exception) -> None:
    """Refuses what is not well-formed XML 1.0 when names are read as plain names, as tinyxml2
    reads them: expat without namespace processing, strict (content after the root element,
    unclosed tags, repeated attributes, undefined entities), external entities never read.
    libxml2's recovery alone let content after the root pass once a namespace error was found.

    Raises:
        MalformedXMLError: where expat stops.
    """
    from xml.parsers import expat

    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(text.encode(), True)
    except expat.ExpatError as exc:
        message = expat.ErrorString(exc.code) if exc.code is not None else str(exc)
        raise MalformedXMLError(source, exc.lineno, exc.offset + 1, message) from first


def _parse_as_tinyxml(text: str, source: str, first: Exception) -> Any:
    """`text` parsed as sdformat's tinyxml2 reads it, which knows nothing of XML namespaces: a
    prefix nobody declared (`<gz:policies>`, `gz:expressed_in=`, gz-sim's own example worlds)
    or a name such as `gz::system_priority` is a plain name there. libxml2 reports those as
    namespace errors and, recovering, keeps the name as written; any other error is refused.

    Raises:
        MalformedXMLError: an error tinyxml2 refuses too (the first one, at its line).
    """
    from lxml import etree

    _check_well_formed(text, source, first)
    parser = etree.XMLParser(
        remove_comments=True, resolve_entities=False, no_network=True, recover=True
    )
    try:
        root = etree.fromstring(text.encode(), parser)
    except etree.XMLSyntaxError as real:
        line, column = real.position
        raise MalformedXMLError(source, line, column, real.msg) from first
    errors = [e for e in parser.error_log if e.domain_name != "NAMESPACE"]
    if root is None or errors:
        error = errors[0] if errors else parser.error_log.last_error
        line, column = (error.line, error.column) if error is not None else (1, 0)
        raise MalformedXMLError(source, line, column, error.message if error else "empty")
    return root


def _name_custom_parts(root: Any) -> None:
    """Elements in a default namespace (no prefix) get their plain name. A prefixed element
    keeps its qualified name (`{uri}name`, or `gz:name` when the prefix was never declared),
    so no reader takes a custom element (`<gz:link>`) for an SDFormat one: libsdformat copies
    custom elements and never reads them."""
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.startswith("{") and not element.prefix:
            element.tag = element.tag.split("}", 1)[1]


def parse_document(text: str, source: str) -> Any:
    """The `<sdf>` root element of `text`, with line numbers; namespaces stripped.

    Raises:
        MalformedXMLError: not well-formed.
        SDFError: the root is not `<sdf>`, or its version is not one twin reads.
    """
    from lxml import etree

    parser = etree.XMLParser(remove_comments=True, resolve_entities=False, no_network=True)
    try:
        root = etree.fromstring(text.encode(), parser)
    except etree.XMLSyntaxError as exc:
        root = _parse_as_tinyxml(_as_tinyxml_reads(text), source, exc)
    _name_custom_parts(root)
    if root.tag != "sdf":
        raise SDFError(
            source,
            line_of(root),
            f"<{root.tag}>",
            "the root element is not <sdf>",
            "give an SDF file",
        )
    version = (root.get("version") or "").strip()
    if version not in VERSIONS:
        raise SDFError(
            source,
            line_of(root),
            "<sdf>",
            f"version {version or '(none)'!r} is not one twin reads",
            f"write version= one of {', '.join(VERSIONS)}",
        )
    return root


def read_pose(ctx: SdfContext, parent: Any) -> tuple[np.ndarray, str | None]:
    """The `<pose>` child of `parent` as 4×4 and its `relative_to` (None when not given).

    SDF 1.9+ also accepts `rotation_format="quat_xyzw"` (7 numbers) and `degrees="true"`.
    A 1.4-1.6 `<pose frame="F">` is `relative_to="F"`: sdformat's 1.6 → 1.7 upgrade renames it.
    """
    element = parent.find("pose")
    if element is None:
        return np.eye(4), None
    raw = (element.text or "").split()
    quat = element.get("rotation_format") == "quat_xyzw"
    expected = 7 if quat else 6
    if raw and len(raw) != expected:
        raise ctx.error(
            element, f"has {len(raw)} numbers", f"write {expected} numbers: x y z and the rotation"
        )
    values = tuple(ctx.parse_number(element, v) for v in raw) or (0.0,) * 6
    if quat and not raw:  # an empty pose is the identity in either format
        values = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    if quat:
        T = np.eye(4)
        T[:3, :3] = quat_matrix(values[3:])
        T[:3, 3] = values[:3]
    else:
        if (element.get("degrees") or "").lower() == "true":
            values = values[:3] + tuple(math.radians(v) for v in values[3:])
        T = pose_matrix(values)
    relative_to = element.get("relative_to") or None
    if relative_to is None and ctx.before_frames(element):
        relative_to = element.get("frame") or None
    return T, relative_to
