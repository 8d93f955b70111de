"""SDFormat frame errors: each names the file and line, the offending frame and what is wrong.

The invalid models of the pose-frame-semantics proposal, our names: a `relative_to`,
`attached_to` or `expressed_in` naming no frame in scope, `relative_to` cycles (a link posed
from itself, two links from each other, a child link posed from its joint whose pose defaults
to that child), `attached_to` cycles; an SDF version twin does not read; a `model://` include
found nowhere (the message lists the places searched).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from sdf_frame_models import (
    LIMIT,
    link,
    write,
)

from converters import convert
from converters.errors import ConversionError


def _error(path: Path) -> str:
    with pytest.raises(ConversionError) as caught:
        convert(path)
    return str(caught.value)


def _line_of(text: str, needle: str) -> int:
    return next(n for n, line in enumerate(text.splitlines(), 1) if needle in line)


def _assert_names(message: str, path: Path, lines: list[int], names: list[str]) -> None:
    assert any(f"{path.name}:{line}" in message for line in lines), (
        f"message names {path.name}:LINE for one of lines {lines}: {message}"
    )
    for name in names:
        assert name in message, f"message names {name!r}: {message}"


# Each case: the model's elements, one a line; the faulty reference is alone on its line.
L1_L2 = [link("L1"), link("L2")]
FIXED_L1_L2 = '<joint name="J0" type="fixed"><parent>L1</parent><child>L2</child></joint>'
UNKNOWN_REFERENCES = {
    "link relative_to": (
        [
            link("L1"),
            link("L2", "0 0 1 0 0 0", relative_to="nowhere"),
            FIXED_L1_L2,
        ],
        "nowhere",
    ),
    "frame relative_to": (
        [link("L1"), '<frame name="F"><pose relative_to="nowhere"/></frame>'],
        "nowhere",
    ),
    "frame attached_to": ([link("L1"), '<frame name="F" attached_to="nowhere"/>'], "nowhere"),
    "joint relative_to": (
        [
            *L1_L2,
            '<joint name="J" type="fixed"><pose relative_to="nowhere"/>'
            "<parent>L1</parent><child>L2</child></joint>",
        ],
        "nowhere",
    ),
    "axis expressed_in": (
        [
            *L1_L2,
            '<joint name="J" type="revolute"><parent>L1</parent><child>L2</child>'
            f'<axis><xyz expressed_in="nowhere">0 0 1</xyz>{LIMIT}</axis></joint>',
        ],
        "nowhere",
    ),
    "nested scope": (
        [
            link("L1"),
            '<model name="arm">' + link("hand") + "</model>",
            '<joint name="J0" type="fixed"><parent>L1</parent><child>arm::hand</child></joint>',
            '<frame name="F" attached_to="arm::nowhere"/>',
        ],
        "arm::nowhere",
    ),
}


@pytest.mark.parametrize("case", sorted(UNKNOWN_REFERENCES))
def test_unknown_frame_reference_names_file_line_and_frame(tmp_path: Path, case: str) -> None:
    elements, name = UNKNOWN_REFERENCES[case]
    body = '<model name="m">\n' + "\n".join(elements) + "\n</model>"
    path = write(tmp_path, body, name="unknown_frame.sdf")
    message = _error(path)
    _assert_names(message, path, [_line_of(path.read_text(), name)], [name])


# Each case: the elements after a root link `base`, and the names the message must give.
CYCLES = {
    # A link posed from itself.
    "self": ([link("cycle0", "0 0 0 0 0 0", relative_to="cycle0")], ["cycle0"], ["cycle0"]),
    # Two links posed from each other.
    "two links": (
        [
            link("cycle1", "0 0 0 0 0 0", relative_to="cycle2"),
            link("cycle2", "0 0 0 0 0 0", relative_to="cycle1"),
        ],
        ["cycle1", "cycle2"],
        ["cycle1", "cycle2"],
    ),
    # The proposal's J3/C3: the child posed from its joint, the joint (by default) from its child.
    "joint and child": (
        [
            link("C3", "0 0 0 0 0 0", relative_to="J3"),
            '<joint name="J3" type="fixed"><parent>base</parent><child>C3</child></joint>',
        ],
        ["C3", "J3"],
        ["C3", "J3"],
    ),
    # Two frames attached to each other (their poses are fine: relative to base); a message
    # naming either frame is enough.
    "attached_to": (
        [
            '<frame name="F1" attached_to="F2"><pose relative_to="base"/></frame>',
            '<frame name="F2" attached_to="F1"><pose relative_to="base"/></frame>',
        ],
        ["F1", "F2"],
        [],
    ),
}


@pytest.mark.parametrize("case", sorted(CYCLES))
def test_frame_cycle_names_file_line_and_frames(tmp_path: Path, case: str) -> None:
    elements, in_cycle, named = CYCLES[case]
    body = '<model name="m">\n' + link("base") + "\n" + "\n".join(elements) + "\n</model>"
    path = write(tmp_path, body, name="cycle.sdf")
    message = _error(path)
    text = path.read_text()
    lines = [_line_of(text, f'name="{name}"') for name in in_cycle]
    _assert_names(message, path, lines, named)
    assert any(name in message for name in in_cycle), f"message names the cycle: {message}"


def test_unknown_sdf_version_names_file_line_and_version(tmp_path: Path) -> None:
    path = write(tmp_path, '<model name="m">' + link("L") + "</model>", version="2.0")
    message = _error(path)
    # The <sdf> root is on line 2, after the XML declaration.
    _assert_names(message, path, [2], ["2.0"])
    assert "1.7" in message or "1.11" in message, (
        f"message lists the versions twin reads: {message}"
    )


def test_missing_model_include_lists_the_places_searched(tmp_path: Path, monkeypatch) -> None:
    searched = tmp_path / "my_models"
    searched.mkdir()
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(searched))
    body = (
        '<model name="m">\n'
        + link("L")
        + "\n<include><uri>model://no_such_model</uri></include>\n</model>"
    )
    path = write(tmp_path, body, name="include.sdf")
    message = _error(path)
    _assert_names(message, path, [_line_of(path.read_text(), "<include>")], ["no_such_model"])
    assert str(searched) in message, f"message lists GAZEBO_MODEL_PATH's {searched}: {message}"
