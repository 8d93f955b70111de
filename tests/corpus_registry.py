"""The corpus of real robot packages (../shared/corpus): where it is and what robots.toml lists.

A clone on its own has no `../shared`: every test that needs the corpus is then skipped while
pytest collects, with `CORPUS_MISSING` as its reason, and the run's summary counts them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pytest
import tomllib

REPO_ROOT = Path(__file__).resolve().parent.parent
CORPUS_ROOT = REPO_ROOT.parent / "shared" / "corpus"
PACKAGES_ROOT = CORPUS_ROOT / "packages"
CORPUS_MISSING = (
    f"corpus: {CORPUS_ROOT} not found (the real robot packages the project is tested with; "
    "CI has them)"
)


def corpus_robots() -> list[dict[str, Any]]:
    """The `[[robot]]` entries of robots.toml (empty when the corpus is absent)."""
    manifest = CORPUS_ROOT / "robots.toml"
    if not manifest.is_file():
        return []
    return tomllib.loads(manifest.read_text())["robot"]


CORPUS = {robot["id"]: robot for robot in corpus_robots()}
# Robots whose upstream inertias are non-physical: they must fail, then convert with repair.
NON_PHYSICAL_INERTIA = ("abb_irb2400_12_155", "anymal_c", "hyq")
# Robots whose <gazebo reference>s name a link they do not have: converted without those tags,
# with a warning, as Gazebo loads them; refused with --strict (robots.toml measured them).
DANGLING = tuple(
    robot_id
    for robot_id, robot in CORPUS.items()
    if robot.get("gazebo_references_to_missing_links")
)
# Marks a test (or a module, as `pytestmark`) that reads the corpus.
needs_corpus = pytest.mark.skipif(not CORPUS, reason=CORPUS_MISSING)


def corpus_ids(ids: Iterable[str] | None = None) -> list[Any]:
    """Parameters over corpus robot ids (all of them by default).

    Without the corpus: one placeholder, skipped with `CORPUS_MISSING`, so that the test is
    reported as skipped rather than silently collected as nothing.
    """
    if not CORPUS:
        return [pytest.param(None, id="no-corpus", marks=pytest.mark.skip(reason=CORPUS_MISSING))]
    return sorted(CORPUS) if ids is None else list(ids)


def corpus_ids_expecting(failures: Mapping[str, str]) -> list[Any]:
    """`corpus_ids()` with each robot of `failures` a strict xfail whose reason is its measured
    figure: a robot that does not meet a test's bound is reported, never dropped from the list,
    and a robot that starts to meet it fails the test until the entry goes."""
    unknown = set(failures) - set(CORPUS) if CORPUS else set()
    assert not unknown, f"expected failures name robots the corpus lacks: {sorted(unknown)}"
    return [
        pytest.param(r, marks=pytest.mark.xfail(reason=failures[r], strict=True))
        if isinstance(r, str) and r in failures
        else r
        for r in corpus_ids()
    ]


def package_paths(robot: dict[str, Any]) -> dict[str, Path]:
    """`--package NAME=PATH` for every package a corpus robot lists."""
    return {name: PACKAGES_ROOT / name for name in robot["packages"]}
