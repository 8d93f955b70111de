"""xacro → URDF text without ROS: `--arg` mappings, `$(find pkg)` through our resolver."""

from __future__ import annotations

import contextlib
import contextvars
import io
import re
import threading
import xml.dom.minidom
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import cast

from converters.errors import ConversionError, XacroError
from converters.resources.packages import PackageResolver

# xacro keeps its substitution context and our patched `find` in module globals.
_LOCK = threading.Lock()

XACRO_SUFFIXES = (".xacro",)
XACRO_MARKERS = ("<xacro:",) + tuple(  # in a file with another suffix: written in xacro
    f"$({name}" for name in ("find ", "arg ", "env ", "optenv ", "eval ", "dirname)")
)
"""Tags and substitution args (xacro's `$(...)`: what only xacro evaluates in a file's text)."""
_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
FOUND: contextvars.ContextVar[dict[str, str]] = contextvars.ContextVar("xacro_found")
"""Packages `$(find)` resolved in the current expansion: name → directory (for messages)."""


@dataclass(frozen=True)
class XacroResult:
    """Expanded URDF text plus what xacro left behind.

    Attributes:
        text: the URDF XML.
        unexpanded: tags that match a macro name but lacked the `xacro:` prefix (never expanded).
        warnings: lines xacro printed to stderr while processing.
    """

    text: str
    unexpanded: tuple[str, ...]
    warnings: tuple[str, ...]


def needs_xacro(path: Path) -> bool:
    """True for files named `.xacro` anywhere in their suffixes (`.urdf.xacro`, `.xacro.urdf`)
    and for any other file written in xacro.

    ROS launch files run xacro on whatever file they are given, so packages ship xacro under
    other names (gz_ros2_control_demos' `test_diff_drive.xacro.urdf`); such a file uses xacro's
    tags or only its substitution args (a `$(find pkg)` path in a `<parameters>` tag). The
    namespace declaration alone does not count: URDFs that xacro already expanded keep it, and
    some carry text placeholders (turtlebot3's `${namespace}`, which its launch file replaces)
    that xacro would refuse.
    """
    return xacro_marker(path) is not None


def xacro_marker(path: Path) -> str | None:
    """What makes `path` xacro (`needs_xacro`): its `.xacro` suffix, the first xacro tag or
    substitution arg in its text, or None. Substitution args count outside XML comments only
    (xacro leaves comments as they are, and URDFs note the command that made them there)."""
    suffix = next((s for s in path.suffixes if s.lower() in XACRO_SUFFIXES), None)
    if suffix is not None:
        return suffix
    try:
        text = path.read_text(errors="replace")
    except OSError:
        return None
    if XACRO_MARKERS[0] in text:
        return XACRO_MARKERS[0]
    code = _COMMENT.sub("", text)
    return next((m for m in XACRO_MARKERS[1:] if m in code), None)


@contextlib.contextmanager
def _patched_find(resolver: PackageResolver) -> Iterator[list[str]]:
    """Make xacro's `$(find pkg)` and `find()` use `resolver`; records the macro names seen."""
    import xacro
    from xacro import substitution_args as subst

    def find(pkg: str) -> str:
        found = resolver.find_package(pkg, uri=f"$(find {pkg})", element=_where())
        FOUND.get()[pkg] = str(found)
        return str(found)

    macro_names: list[str] = []
    original_grab = xacro.grab_macro

    def grab_macro(elt: xml.dom.minidom.Element, macros: object) -> None:
        name = elt.getAttribute("name")
        macro_names.append(name[6:] if name.startswith("xacro:") else name)
        original_grab(elt, macros)

    # xacro has no hook for $(find): its substitution table is the one place to put ours.
    saved = (subst._eval_find, subst._eval_dict["find"])  # noqa: SLF001
    subst._eval_find = find  # noqa: SLF001
    subst._eval_dict["find"] = find  # noqa: SLF001
    xacro.grab_macro = grab_macro
    try:
        yield macro_names
    finally:
        subst._eval_find, subst._eval_dict["find"] = saved  # noqa: SLF001
        xacro.grab_macro = original_grab


def _where() -> str:
    """The xacro file being expanded now (xacro's file stack), for a `$(find)` message."""
    import xacro

    stack = getattr(xacro, "filestack", None) or []
    current = next((f for f in reversed(stack) if f), None)
    return f"xacro $(find) in {current}" if current else "xacro $(find)"


def _conversion_cause(exc: BaseException) -> ConversionError | None:
    """Our own error if xacro wrapped one (e.g. an unknown package inside `$(find)`)."""
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, ConversionError):
            return seen
        inner = getattr(seen, "exc", None)
        seen = inner if isinstance(inner, BaseException) else (seen.__cause__ or seen.__context__)
    return None


def _xacro_error(path: Path, exc: BaseException) -> XacroError:
    """xacro's failure, said once; a missing include names the package it was looked for in
    (a source checkout or another version of the package lacks files its install has)."""
    if _caused_by(exc, RecursionError):
        return XacroError(
            str(path),
            "macros or includes nest without end (maximum recursion depth exceeded)",
            "look for a macro that calls itself with no stopping condition, or a file that "
            "includes itself through others",
        )
    missing = _missing_file(exc)
    if missing is None:
        return XacroError(str(path), str(exc) or type(exc).__name__)
    owners = [(pkg, root) for pkg, root in FOUND.get().items() if missing.startswith(root + "/")]
    owner = max(owners, key=lambda o: len(o[1]), default=None)  # the innermost package
    if owner is None:
        return XacroError(str(path), f"{missing} does not exist", "fix the include's filename")
    pkg, root = owner
    return XacroError(
        str(path),
        f"{missing} does not exist in package '{pkg}', found at {root}",
        f"that copy of '{pkg}' lacks the file (a source checkout, or a version other than the "
        f"robot was written for); give the right one with --package {pkg}=PATH",
    )


def _caused_by(exc: BaseException, kind: type[BaseException]) -> bool:
    """Whether `exc` or an exception it wraps (xacro's `.exc`, a cause) is a `kind`."""
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, kind):
            return True
        inner = getattr(seen, "exc", None)
        seen = inner if isinstance(inner, BaseException) else (seen.__cause__ or seen.__context__)
    return False


def _missing_file(exc: BaseException) -> str | None:
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, FileNotFoundError) and seen.filename:
            return str(seen.filename)
        inner = getattr(seen, "exc", None)
        seen = inner if isinstance(inner, BaseException) else (seen.__cause__ or seen.__context__)
    return None


def expand_xacro(path: Path, args: Mapping[str, str], resolver: PackageResolver) -> XacroResult:
    """Run xacro on `path` with `args` (the `NAME:=VALUE` mappings).

    Raises:
        XacroError: xacro failed; the message is xacro's own, with the file.
        PackageNotFoundError: a `$(find pkg)` names an unknown package.
    """
    import xacro

    stderr = io.StringIO()
    FOUND.set({})
    with _LOCK, _patched_find(resolver) as macro_names, contextlib.redirect_stderr(stderr):
        try:
            # xacro has no annotations; process_file returns the expanded DOM document.
            doc = cast(xml.dom.minidom.Document, xacro.process_file(str(path), mappings=dict(args)))
        except Exception as exc:  # xacro raises many types (XacroException, NameError, …)
            ours = _conversion_cause(exc)
            if ours is not None:
                raise ours from exc
            raise _xacro_error(path, exc) from exc
        finally:
            xacro.init_stacks(None)
    unexpanded = _unexpanded_calls(doc, set(macro_names))
    warnings = tuple(line for line in stderr.getvalue().splitlines() if line.strip())
    return XacroResult(doc.toxml(), unexpanded, warnings)


def _unexpanded_calls(doc: xml.dom.minidom.Document, macro_names: set[str]) -> tuple[str, ...]:
    """Tags left in the output whose name is a macro's: calls written without `xacro:`."""
    found: list[str] = []
    root = doc.documentElement
    if root is None:
        return ()
    for node in root.getElementsByTagName("*"):
        tag = node.tagName.split(":")[-1]
        if tag in macro_names:
            attrs = " ".join(f'{k}="{v}"' for k, v in node.attributes.items())
            found.append(f"<{node.tagName}{' ' + attrs if attrs else ''}/>")
    return tuple(found)
