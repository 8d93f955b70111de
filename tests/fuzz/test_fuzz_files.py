"""Fuzzed description files: every mutation converts, or fails with one ConversionError.

A bounded, derandomised run is part of `make test`; `make fuzz` runs the same properties for a
time budget (`TWIN_FUZZ_SECONDS`) and reports cases per second. A failure Hypothesis finds is
shrunk to a minimal file; keep it as a regression case in tests/fuzz/regressions/.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mutations import mutated

from converters.errors import ConversionError
from converters.pipeline import convert_text

ROOT = Path(__file__).resolve().parents[2]
REGRESSIONS = Path(__file__).resolve().parent / "regressions"
SEEDS = {
    "urdf": (ROOT / "tests" / "fuzz" / "seeds" / "arm.urdf").read_text(),
    "sdf": (ROOT / "tests" / "fuzz" / "seeds" / "world_model.sdf").read_text(),
}
# Bounded in `make test`; `make fuzz` raises it (TWIN_FUZZ_EXAMPLES) and sets a deadline.
EXAMPLES = int(os.environ.get("TWIN_FUZZ_EXAMPLES", "150"))
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize="TWIN_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    database=None,
)


def converts_or_explains(text: str, source: str) -> None:
    """The property: a model, or a ConversionError whose message names the source."""
    try:
        convert_text(text, source=source, base_dir=ROOT / "tests" / "fuzz" / "seeds")
    except ConversionError as exc:
        assert source in str(exc) or "<" in str(exc), f"message names no place: {exc}"


@pytest.mark.parametrize("kind", sorted(SEEDS))
def test_mutated_descriptions_convert_or_explain(kind: str) -> None:
    @FUZZ
    @given(text=mutated(SEEDS[kind]))
    def run(text: str) -> None:
        converts_or_explains(text, f"fuzz.{kind}")

    run()


@pytest.mark.parametrize("case", sorted(REGRESSIONS.glob("*")), ids=lambda p: p.name)
def test_regressions_convert_or_explain(case: Path) -> None:
    converts_or_explains(case.read_text(errors="replace"), case.name)


@FUZZ
@given(junk=st.text(max_size=200))
def test_any_text_converts_or_explains(junk: str) -> None:
    converts_or_explains(junk, "junk.urdf")
