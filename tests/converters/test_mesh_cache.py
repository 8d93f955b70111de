"""The collision cache: keys, atomic writes under two processes, reuse without CoACD, CLI."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from collision_models import box_mesh, cup_mesh, request
from typer.testing import CliRunner

from converters.collision import cache as mesh_cache
from converters.collision.decompose import FAULT_ENV
from converters.collision.plan import CollisionSettings
from converters.collision.prepare import prepare_collision_meshes
from converters.report import Report


@pytest.fixture(autouse=True)
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv(mesh_cache.ENV_CACHE_DIR, str(tmp_path / "cache"))
    return tmp_path / "cache" / mesh_cache.SUBDIR


def _parts(seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(rng.random((8, 3)), rng.integers(0, 8, (12, 3))) for _ in range(3)]


def test_store_then_load_returns_identical_arrays_and_meta(cache_dir):
    parts = _parts()
    mesh_cache.store("k1", parts, {"mode": "coacd"})
    hit = mesh_cache.load("k1")
    assert hit is not None and hit.meta["mode"] == "coacd"
    for (v0, f0), (v1, f1) in zip(parts, hit.parts, strict=True):
        assert np.array_equal(v0, v1) and np.array_equal(f0, f1), "stored part arrays"
    assert mesh_cache.info().entries == 1 and mesh_cache.info().path == cache_dir


def test_key_changes_with_mesh_scale_parameters_and_coacd_version():
    vertices, faces = box_mesh((0.1, 0.1, 0.1))
    facts = {"scale": [1, 1, 1], "threshold": 0.05}
    base = mesh_cache.entry_key(vertices, faces, facts)
    assert base == mesh_cache.entry_key(vertices, faces, facts, version=mesh_cache.coacd_version())
    variants = {
        "mesh bytes": mesh_cache.entry_key(vertices * 1.001, faces, facts),
        "scale": mesh_cache.entry_key(vertices, faces, {**facts, "scale": [2, 1, 1]}),
        "parameters": mesh_cache.entry_key(vertices, faces, {**facts, "threshold": 0.1}),
        "coacd version": mesh_cache.entry_key(vertices, faces, facts, version="0.0.0"),
    }
    for what, key in variants.items():
        assert key != base, f"cache key must change with {what}"


def test_damaged_entry_is_a_miss_and_is_removed(cache_dir):
    mesh_cache.store("bad", _parts(), {})
    (cache_dir / "bad.npz").write_bytes(b"not a zip file")
    assert mesh_cache.load("bad") is None, "damaged entry reads as a miss"
    assert not (cache_dir / "bad.npz").exists(), "damaged entry removed"


WRITER = textwrap.dedent(
    """
    import sys, numpy as np
    from converters.collision import cache as mesh_cache
    rng = np.random.default_rng(0)
    parts = [(rng.random((5000, 3)), rng.integers(0, 5000, (10000, 3))) for _ in range(4)]
    for _ in range(int(sys.argv[1])):
        mesh_cache.store("shared", parts, {"writer": "same"})
        hit = mesh_cache.load("shared")
        assert hit is not None and len(hit.parts) == 4, "reader saw a partial entry"
        assert np.array_equal(hit.parts[3][0], parts[3][0]), "reader saw mixed bytes"
    """
)


def test_two_processes_writing_the_same_entry_never_expose_a_partial_file(cache_dir):
    procs = [
        subprocess.Popen([sys.executable, "-c", WRITER, "15"], stderr=subprocess.PIPE)
        for _ in range(2)
    ]
    errors = [p.communicate(timeout=120)[1].decode() for p in procs]
    assert [p.returncode for p in procs] == [0, 0], f"writer errors: {errors}"
    assert [p.name for p in cache_dir.iterdir()] == ["shared.npz"], "no temporary files left"


def test_second_conversion_makes_no_coacd_call_and_returns_identical_parts(monkeypatch):
    requests = [request("cup/0", cup_mesh(10)), request("box/0", box_mesh((0.1, 0.2, 0.3)))]
    settings = CollisionSettings(mode="auto", preset="fast")
    first_report, second_report = Report(), Report()
    first = prepare_collision_meshes(requests, settings, first_report)
    # Any CoACD worker started now would crash and leave a hull fallback in the report.
    monkeypatch.setenv(FAULT_ENV, "crash:*")
    second = prepare_collision_meshes(requests, settings, second_report)
    assert first_report.summary["collision"]["coacd_runs"] == 1, "first run decomposes the cup"
    assert second_report.summary["collision"]["coacd_runs"] == 0, "CoACD runs on second call"
    assert [row["cache"] for row in second_report.meshes] == ["hit", "hit"]
    assert all(row["fallback"] is None for row in second_report.meshes), "no worker was started"
    for key in first:
        assert len(first[key]) == len(second[key]), f"{key}: part count"
        for a, b in zip(first[key], second[key], strict=True):
            assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)
    assert [e.detail for e in first_report.entries] == [e.detail for e in second_report.entries]


def test_no_cache_setting_neither_reads_nor_writes(cache_dir):
    settings = CollisionSettings(mode="hull", use_cache=False)
    report = Report()
    prepare_collision_meshes([request("box/0", box_mesh((0.1, 0.1, 0.1)))], settings, report)
    assert report.meshes[0]["cache"] == "off" and not cache_dir.exists(), "cache untouched"


def test_cli_cache_info_and_clear(cache_dir):
    from twin_cli.cli.app import app

    mesh_cache.store("a", _parts(1), {})
    mesh_cache.store("b", _parts(2), {})
    runner = CliRunner()
    info = runner.invoke(app, ["cache", "info", "--json"])
    assert info.exit_code == 0, info.output
    facts = json.loads(info.output)
    assert facts["path"] == str(cache_dir) and facts["entries"] == 2 and facts["bytes"] > 0
    cleared = runner.invoke(app, ["cache", "clear"])
    assert cleared.exit_code == 0 and "Removed 2" in cleared.output, cleared.output
    assert json.loads(runner.invoke(app, ["cache", "info", "--json"]).output)["entries"] == 0
