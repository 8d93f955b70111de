"""Fuzzed scenario TOML, `--arg` and `-J` values: a result, or one known error naming the input.

Scenario files are mutated from the bundled ones (keys deleted, values replaced by garbage and
extreme numbers, truncated, binary junk); `--arg` values go into the bundled humanoid's xacro
(`foot_mu`, `with_head`); `-J` values go through the command line's parser. The property: no
exception other than twin's own (ScenarioError, ConversionError, BadOption), each naming the
file, key or option. Bounded in `make test` (TWIN_FUZZ_EXAMPLES raises it in `make fuzz`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import tomllib
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import scenarios
from converters.errors import ConversionError
from twin_cli.cli.pairs import BadOption, joint_positions, source_inputs
from twin_cli.errors import ScenarioError
from twin_cli.validate.scenario import load_scenario

ROOT = Path(scenarios.__file__).resolve().parent
SEEDS = sorted(ROOT.glob("*.toml"))
EXAMPLES = int(os.environ.get("TWIN_FUZZ_EXAMPLES", "100"))
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize="TWIN_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=list(HealthCheck),
    database=None,
)
GARBAGE = st.sampled_from(
    [
        "nan",
        "inf",
        "-inf",
        "1e309",
        "-1",
        "0",
        '""',
        '"x"',
        "[]",
        "{}",
        "true",
        "-1e-320",
        '"earth"',
        "[1, 2]",
        '"\\u0000"',
        "1979-05-27",
    ]
)


@st.composite
def mutated_toml(draw) -> str:
    """A bundled scenario with one to three lines changed, or truncated, or with junk added."""
    lines = draw(st.sampled_from(SEEDS)).read_text().splitlines()
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["delete", "value", "key", "dup"]))
        if kind == "delete":
            del lines[i]
        elif kind == "value" and "=" in lines[i]:
            lines[i] = lines[i].split("=", 1)[0] + "= " + draw(GARBAGE)
        elif kind == "key" and "=" in lines[i]:
            lines[i] = draw(st.sampled_from(["bogus", "duration", "check", "name"])) + " = 1"
        elif kind == "dup":
            lines.insert(i, lines[i])
        if not lines:
            break
    text = "\n".join(lines)
    if draw(st.booleans()):
        text = text[: draw(st.integers(0, len(text)))]
    return text + draw(st.sampled_from(["", "\n\x00\xff", "\n[robot\n", "\n[[x]]\n"]))


def test_mutated_scenarios_load_or_name_the_file_and_key(tmp_path) -> None:
    path = tmp_path / "fuzzed.toml"

    @FUZZ
    @given(text=mutated_toml())
    def run(text: str) -> None:
        path.write_text(text, encoding="utf-8", errors="surrogateescape")
        try:
            load_scenario(path)
        except ScenarioError as exc:
            assert str(path) in str(exc), f"message names no file: {exc}"

    run()


def test_bundled_scenarios_are_valid_seeds() -> None:
    for seed in SEEDS:
        tomllib.loads(seed.read_text())
        load_scenario(seed)


TEXT = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=20)


@FUZZ
@given(
    items=st.lists(st.one_of(TEXT, st.builds(lambda n, v: f"{n}={v}", TEXT, GARBAGE)), max_size=4)
)
@example(items=["=NAN"])  # found by this fuzz: an empty joint name and a NaN position passed
@example(items=["elbow=1e309"])
def test_J_values_parse_to_finite_numbers_or_name_the_option(items: list[str]) -> None:
    try:
        joints = joint_positions(items)
    except BadOption as exc:
        assert "-J" in str(exc), f"message names no option: {exc}"
        return
    assert all(name and math.isfinite(v) for name, v in joints.items()), joints


@settings(FUZZ, max_examples=max(10, EXAMPLES // 5))
@given(
    mu=st.one_of(GARBAGE, TEXT, st.floats(allow_nan=True).map(repr)),
    head=st.one_of(st.sampled_from(["true", "false", "1", "0", "", "yes"]), TEXT),
)
def test_xacro_args_convert_or_explain(mu: str, head: str) -> None:
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert

    try:
        inputs = source_inputs([f"foot_mu:={mu}", f"with_head:={head}"], None)
        convert(
            scenarios.HUMANOID,
            args=inputs["args"],
            options=ConvertOptions(collision=CollisionSettings(mode="hull")),
        )
    except (ConversionError, BadOption) as exc:
        assert str(exc).strip(), "an empty message"
