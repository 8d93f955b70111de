"""Fuzzed include and xacro attacks on a served conversion: a model, one ConversionError (exit 2)
or a budget refusal; never another exception (exit 70, HTTP 500), never a hang, never a secret.

SDF: `model://` include graphs (cycles, self-includes, merges, deep chains, fan-outs) and
`file://` URIs to a file outside the models. URDF/xacro: macros fanning out exponentially, macros
recursing without end, include circles, includes and `load_yaml` of files outside the package,
`$(env)` and `$(optenv)` of a server variable. The planted secret (a file's content, a server
variable's value) must appear in no result and no message. Each case runs the world's path
(`converters.serving.served`, a bounded child) under a small budget. The attacks found so far are
fixed cases below. Bounded in `make test`; `make fuzz` raises the example count.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from converters.errors import (
    ConversionBudgetError,
    ConversionError,
    PackageNotFoundError,
    SDFError,
    XacroError,
)
from converters.isolated import bounded
from converters.isolated.budget import XacroBudget
from converters.mjcf.builder import ConvertOptions
from converters.serving.served import ConversionJob, convert_served

# 5 s: the bounded child's own start (Python, xacro, the converter) is part of the budget, and
# on a runner with two busy loops per core it alone passed 2 s, so that every attack, refused in
# well under a second when quiet, came back as a budget refusal instead of its own.
BUDGET = XacroBudget(timeout_s=5.0, memory_mib=2048)
SLACK_S = 5.0  # [s] past the budget: the child's start and the caller's own work
SECRET_TEXT, SECRET_VALUE, SECRET_VAR = "hunter2", "server-secret", "TWIN_FUZZ_SECRET"
# Each case starts a child (and a xacro grandchild): fewer cases than the file fuzzers.
EXAMPLES = max(4, int(os.environ.get("TWIN_FUZZ_EXAMPLES", "40")) // 10)
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize="TWIN_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=list(HealthCheck),
    database=None,
)
INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
    "</inertial>"
)
XACRO_HEAD = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
BASE = f'<link name="base">{INERTIAL}</link>'


@pytest.fixture(autouse=True, scope="module")
def bounded_here():
    """Conversions in this module run as a world server's do (`bounded.enable`)."""
    bounded.enable()
    yield
    bounded.disable()


def attempt(path: Path, env: dict[str, str] | None = None) -> ConversionError | None:
    """Convert `path` as a world does; the ConversionError it raised, or None.

    Fails the test on any exception other than a ConversionError, on a conversion that outlived
    its budget, and on a secret in the outcome.
    """
    env = {**os.environ, SECRET_VAR: SECRET_VALUE, **(env or {})}
    options = ConvertOptions(xacro_budget=BUDGET)
    job = ConversionJob(str(path), path=str(path), options=options, env=env)
    start = time.monotonic()
    refusal = None
    try:
        outcome = convert_served(job, BUDGET).description.text
    except ConversionError as exc:
        refusal, outcome = exc, str(exc)
        assert str(path) in outcome or "<" in outcome, f"message names no place: {outcome}"
    took = time.monotonic() - start
    assert took < BUDGET.timeout_s + SLACK_S, f"{path.name}: {took:.1f} s, past its budget"
    assert SECRET_TEXT not in outcome and SECRET_VALUE not in outcome, f"secret out: {outcome}"
    return refusal


def plant_secret(root: Path) -> Path:
    """A file outside every package and model folder, whose content must never come out."""
    secret = root / "secret.yaml"
    secret.write_text(f"token: {SECRET_TEXT}\n")
    return secret


# ------------------------------------------------------------------------------------ SDF
def write_model(models: Path, name: str, uris: list[str], merge: bool = False) -> Path:
    """A Gazebo model folder `name` (model.config, model.sdf) including each of `uris`."""
    folder = models / name
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "model.config").write_text(
        f"<model><name>{name}</name><sdf version='1.9'>model.sdf</sdf></model>"
    )
    flag = ' merge="true"' if merge else ""
    includes = "".join(
        f"<include{flag}><uri>{uri}</uri><name>i{k}</name><pose>{k} 0 0 0 0 0</pose></include>"
        for k, uri in enumerate(uris)
    )
    (folder / "model.sdf").write_text(
        f"<sdf version='1.9'><model name='{name}'><link name='l{name}'>"
        f"<inertial><mass>1</mass></inertial></link>{includes}</model></sdf>"
    )
    return folder / "model.sdf"


@st.composite
def include_graphs(draw) -> tuple[list[list[str]], int, bool]:
    """Which models each of up to five models includes (any graph: cycles, self-includes),
    a chain of model:// includes below model 0, and whether includes merge."""
    count = draw(st.integers(1, 5))
    targets = st.sampled_from(
        [*(f"model://m{i}" for i in range(count)), "model://chain0", "model://missing",
         "model://../../secret.yaml", "file://@SECRET_FILE@", "model://m0/../../secret.yaml"]
    )  # fmt: skip
    edges = [draw(st.lists(targets, max_size=3)) for _ in range(count)]
    return edges, draw(st.integers(0, 150)), draw(st.booleans())


def write_sdf_graph(root: Path, edges: list[list[str]], chain: int, merge: bool) -> Path:
    secret = plant_secret(root)
    models = root / "models"
    for i, uris in enumerate(edges):
        uris = [u.replace("@SECRET_FILE@", str(secret)) for u in uris]
        write_model(models, f"m{i}", uris, merge)
    for i in range(chain):
        write_model(models, f"chain{i}", [f"model://chain{i + 1}"] if i + 1 < chain else [])
    return models / "m0" / "model.sdf"


@FUZZ
@given(graph=include_graphs())
def test_any_include_graph_converts_or_is_refused(graph) -> None:
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        path = write_sdf_graph(root, *graph)
        attempt(path, {"GAZEBO_MODEL_PATH": str(root / "models")})


# ---------------------------------------------------------------------------------- xacro
OUTSIDE = ["../../secret.yaml", "@SECRET_FILE@", "/etc/hostname", "$(find pkg)/urdf/a.xacro",
           "$(find elsewhere)/x.xacro", "r.urdf.xacro", "a.xacro"]  # fmt: skip


@st.composite
def xacro_attacks(draw) -> str:
    """A xacro file built from attack pieces: an exponential macro, a recursing macro, includes
    and `load_yaml` of files inside and outside the package, `$(env)`/`$(optenv)`."""
    parts = [XACRO_HEAD, BASE]
    depth, fan = draw(st.integers(0, 28)), draw(st.integers(1, 3))
    calls = "".join(f"<xacro:m{depth - 1}/>" for _ in range(fan)) if depth else ""
    for level in range(depth):
        inner = "".join(f"<xacro:m{level - 1}/>" for _ in range(fan)) if level else ""
        parts.append(f'<xacro:macro name="m{level}">{inner or "<dummy/>"}</xacro:macro>')
    parts.append(calls)
    recurse = draw(st.integers(0, 5000))
    parts.append(
        '<xacro:macro name="down" params="n"><xacro:if value="${n > 0}">'
        '<xacro:down n="${n-1}"/></xacro:if></xacro:macro>'
        f'<xacro:down n="{recurse}"/>'
    )
    for target in draw(st.lists(st.sampled_from(OUTSIDE), max_size=2)):
        parts.append(f'<xacro:include filename="{target}"/>')
    for target in draw(st.lists(st.sampled_from(OUTSIDE), max_size=1)):
        parts.append(
            f'<xacro:property name="y" value="${{xacro.load_yaml(\'{target}\')}}"/>'
            "<link name=\"${y['token']}\"/>"
        )
    if draw(st.booleans()):
        parts.append(f'<link name="$(env {SECRET_VAR})"/>')
    if draw(st.booleans()):
        parts.append(f'<link name="$(optenv {SECRET_VAR} unset)"/>')
    return "".join(parts) + "</robot>"


def write_package(root: Path, main: str) -> Path:
    """A ROS package `pkg` with `urdf/r.urdf.xacro` = `main` and an `a.xacro` that includes
    the main file back (an include circle when the main file includes it)."""
    secret = plant_secret(root)
    urdf = root / "pkg" / "urdf"
    urdf.mkdir(parents=True)
    (root / "pkg" / "package.xml").write_text("<package><name>pkg</name></package>")
    (urdf / "a.xacro").write_text(f'{XACRO_HEAD}<xacro:include filename="r.urdf.xacro"/></robot>')
    path = urdf / "r.urdf.xacro"
    path.write_text(main.replace("@SECRET_FILE@", str(secret)))
    return path


@FUZZ
@given(main=xacro_attacks())
def test_any_xacro_attack_converts_or_is_refused(main: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        attempt(write_package(root, main), {"ROS_PACKAGE_PATH": str(root / "pkg")})


# ------------------------------------------------------------------ the attacks, kept as cases
def _bomb(depth: int) -> str:
    macros = "".join(
        f'<xacro:macro name="m{i}"><xacro:m{i + 1}/><xacro:m{i + 1}/></xacro:macro>'
        for i in range(depth)
    )
    return f'{macros}<xacro:macro name="m{depth}"><dummy/></xacro:macro><xacro:m0/>'


XACRO_CASES = {
    "power_tower": ('<link name="x${9**9**9}"/>', ConversionBudgetError),
    "macro_bomb_2_25": (_bomb(25), ConversionBudgetError),
    "endless_recursion": (
        '<xacro:macro name="down" params="n"><xacro:down n="${n+1}"/></xacro:macro>'
        '<xacro:down n="0"/>',
        XacroError,
    ),
    "self_include": ('<xacro:include filename="r.urdf.xacro"/>', XacroError),
    "include_circle": ('<xacro:include filename="a.xacro"/>', XacroError),
    "include_outside": ('<xacro:include filename="@SECRET_FILE@"/>', XacroError),
    "include_parent_folder": ('<xacro:include filename="../../secret.yaml"/>', XacroError),
    "load_yaml_outside": (
        '<xacro:property name="y" value="${xacro.load_yaml(\'@SECRET_FILE@\')}"/>'
        "<link name=\"${y['token']}\"/>",
        XacroError,
    ),
    "env_of_the_server": (f'<link name="$(env {SECRET_VAR})"/>', XacroError),
    "find_unknown_package": (
        '<xacro:include filename="$(find elsewhere)/x.xacro"/>',
        PackageNotFoundError,
    ),
}


# What each refusal must say (the subject, without the content).
XACRO_SAYS = {
    "power_tower": "while expanding xacro",
    "macro_bomb_2_25": "while expanding xacro",
    "endless_recursion": "nest without end",
    "self_include": "nest without end",
    "include_circle": "nest without end",
    "include_outside": "secret.yaml is outside the robot's own package",
    "include_parent_folder": "secret.yaml is outside the robot's own package",
    "load_yaml_outside": "secret.yaml is outside the robot's own package",
    "env_of_the_server": SECRET_VAR,
    "find_unknown_package": "$(find) in ",  # the file that asked, found by the fuzzer
}


@pytest.mark.parametrize("case", sorted(XACRO_CASES))
def test_xacro_attack_is_refused_as_it_should(case: str, tmp_path: Path) -> None:
    body, expected = XACRO_CASES[case]
    path = write_package(tmp_path, f"{XACRO_HEAD}{BASE}{body}</robot>")
    refusal = attempt(path, {"ROS_PACKAGE_PATH": str(tmp_path / "pkg")})
    assert isinstance(refusal, expected), f"{case}: {refusal!r}"
    assert XACRO_SAYS[case] in str(refusal), refusal


SDF_CASES = {
    "self_include": ([["model://m0"]], 0, SDFError),
    "two_model_circle": ([["model://m1"], ["model://m0"]], 0, SDFError),
    "merged_circle": ([["model://m1"], ["model://m0"]], 0, SDFError),
    "chain_of_150": ([["model://chain0"]], 150, SDFError),
    "fan_out_2_20": ([["model://m1", "model://m1"]], 0, ConversionBudgetError),
    "file_uri_outside": ([["file://@SECRET_FILE@"]], 0, ConversionError),
}


@pytest.mark.parametrize("case", sorted(SDF_CASES))
def test_sdf_include_attack_is_refused_as_it_should(case: str, tmp_path: Path) -> None:
    edges, chain, expected = SDF_CASES[case]
    if case == "fan_out_2_20":  # m_i includes m_{i+1} twice: 2^20 models
        edges = [[f"model://m{i + 1}"] * 2 for i in range(20)] + [[]]
    path = write_sdf_graph(tmp_path, edges, chain, merge=case == "merged_circle")
    refusal = attempt(path, {"GAZEBO_MODEL_PATH": str(tmp_path / "models")})
    assert isinstance(refusal, expected), f"{case}: {refusal!r}"
