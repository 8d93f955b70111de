"""Shared fixtures: repository and corpus roots, and each corpus robot converted once a session."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from corpus_registry import (
    CORPUS,
    CORPUS_MISSING,
    CORPUS_ROOT,
    NON_PHYSICAL_INERTIA,
    PACKAGES_ROOT,
    REPO_ROOT,
    package_paths,
)

pytest_plugins = ["reaper"]
CORPUS_FIXTURES = {"corpus_root", "converted_corpus"}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Without the corpus, tests that use its fixtures are skipped as they are collected."""
    if CORPUS:
        return
    skip = pytest.mark.skip(reason=CORPUS_MISSING)
    for item in items:
        if CORPUS_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(skip)


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Under `--dist loadgroup`, an `xdist_group` test must carry its group in its node id: that
    is how pytest-xdist sends a group to one worker. A pytest that drops it splits every group over
    the workers (a session fixture built once per worker, a shared server raced) without a word."""
    grouped = item.get_closest_marker("xdist_group") is not None
    if grouped and item.config.getoption("loadgroup", default=False) and "@" not in item.nodeid:
        pytest.fail(
            "--dist loadgroup did not group this test: this pytest and pytest-xdist disagree on "
            "node ids; install the versions the test extra names",
            pytrace=False,
        )


def pytest_terminal_summary(terminalreporter) -> None:
    """One line that says how many tests the missing corpus skipped, and why."""
    skipped = terminalreporter.stats.get("skipped", [])
    missing = [r for r in skipped if CORPUS_MISSING in str(getattr(r, "longrepr", ""))]
    if missing:
        terminalreporter.write_line(f"{len(missing)} tests skipped: {CORPUS_MISSING}", yellow=True)


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return REPO_ROOT


@pytest.fixture(scope="session")
def corpus_root() -> Path:
    if not CORPUS_ROOT.is_dir():
        pytest.skip(CORPUS_MISSING)
    return CORPUS_ROOT


@pytest.fixture(scope="session")
def converted_corpus(corpus_root: Path) -> Callable[[str], Any]:
    """`get(robot_id)` → `converters.pipeline.Conversion`, converted once per session.

    Packages come from `--package` options; inertias are repaired only for the robots listed in
    NON_PHYSICAL_INERTIA; collision meshes use convex hulls (no CoACD, to keep tests fast).
    """
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert_full

    cache: dict[str, Any] = {}

    def get(robot_id: str) -> Any:
        if robot_id not in cache:
            robot = CORPUS[robot_id]
            options = ConvertOptions(
                repair_inertia=robot_id in NON_PHYSICAL_INERTIA,
                collision=CollisionSettings(mode="hull"),
            )
            cache[robot_id] = convert_full(
                PACKAGES_ROOT / robot["entry"],
                args=robot["xacro_args"],
                package_paths=package_paths(robot),
                options=options,
            )
        return cache[robot_id]

    return get
