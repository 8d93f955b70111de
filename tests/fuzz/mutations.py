"""Mutations of real description files, the ways hand-edited files break (Hypothesis strategies).

Deleted elements and attributes, emptied elements, garbage and extreme numbers, truncated
text, duplicated names, a wrong root, unknown joint types and binary junk. Each strategy draws a
mutated text from a seed text; the property under test is the converter's contract: a result,
or one `ConversionError` naming the file, never another exception.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from hypothesis import strategies as st

# Values that break numbers in every way a hand edit or a bad generator does.
BAD_NUMBERS = ("nan", "inf", "-inf", "1e309", "-1", "0", "-0.5", "", "abc", "1,5", "1e-400")


def _elements(root: ET.Element) -> list[ET.Element]:
    return [e for e in root.iter() if e is not root]


@st.composite
def mutated(draw: st.DrawFn, text: str) -> str:
    """One to three mutations of XML `text` (or a truncation / junk of the raw text)."""
    kind = draw(st.sampled_from(("tree", "tree", "tree", "truncate", "junk")))
    if kind == "truncate":
        return text[: draw(st.integers(0, max(len(text) - 1, 0)))]
    if kind == "junk":
        junk = draw(st.binary(min_size=1, max_size=40)).decode("latin-1")
        at = draw(st.integers(0, len(text)))
        return text[:at] + junk + text[at:]
    root = ET.fromstring(text)
    for _ in range(draw(st.integers(1, 3))):
        _mutate_tree(draw, root)
    return ET.tostring(root, encoding="unicode")


def _mutate_tree(draw: st.DrawFn, root: ET.Element) -> None:
    elements = _elements(root)
    if not elements:
        return
    target = draw(st.sampled_from(elements))
    action = draw(
        st.sampled_from(("delete", "empty", "attribute", "number", "duplicate", "rename", "type"))
    )
    if action == "delete":
        parent = next(p for p in root.iter() if target in list(p))
        parent.remove(target)
    elif action == "empty":
        target.clear()
    elif action == "attribute" and target.attrib:
        del target.attrib[draw(st.sampled_from(sorted(target.attrib)))]
    elif action == "number":
        _bad_number(draw, target)
    elif action == "duplicate":
        parent = next(p for p in root.iter() if target in list(p))
        parent.append(ET.fromstring(ET.tostring(target)))
    elif action == "rename":
        target.tag = draw(st.sampled_from(("robot", "link", "joint", "sdf", "model", "frame")))
    elif action == "type" and "type" in target.attrib:
        target.set("type", draw(st.sampled_from(("fixd", "hinge", "", "ball", "universal"))))


def _bad_number(draw: st.DrawFn, target: ET.Element) -> None:
    numeric = [k for k, v in target.attrib.items() if _is_number_list(v)]
    value = draw(st.sampled_from(BAD_NUMBERS))
    if numeric:
        target.set(draw(st.sampled_from(numeric)), value)
    elif target.text and _is_number_list(target.text):
        target.text = value


def _is_number_list(text: str) -> bool:
    try:
        [float(v) for v in text.split()]
    except ValueError:
        return False
    return bool(text.split())
