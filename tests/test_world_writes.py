"""Only `twin_cli/world/` writes a world's MuJoCo model and data; everything else changes the world
through `World`'s methods, which hold its lock and keep its records.

The rule is read from the code's syntax tree: an assignment (`=`, `+=`, …) into something reached
through a `.model` or `.data` attribute (`world.data.ctrl[a] = …`, `self.world.model.opt.x = …`),
or through a local name bound to one (`d = world.data; d.ctrl[a] = …`). Reads are free: other
packages read positions, velocities and sensors. A model a module builds for itself (a
validation check's own compiled copy) is not reached through `.model`, so it may be written.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STATE = {"model", "data"}
OWNER = "twin_cli/world/"


def _functions(tree: ast.AST) -> list[ast.AST]:
    return [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]


def _aliases(function: ast.AST) -> set[str]:
    """Local names bound to `<something>.model` or `<something>.data`."""
    names = set()
    for node in ast.walk(function):
        if not isinstance(node, ast.Assign):
            continue
        for target in node.targets:
            pairs = (
                zip(target.elts, node.value.elts, strict=False)
                if isinstance(target, ast.Tuple) and isinstance(node.value, ast.Tuple)
                else [(target, node.value)]
            )
            for name, value in pairs:
                if isinstance(name, ast.Name) and isinstance(value, ast.Attribute):
                    if value.attr in STATE:
                        names.add(name.id)
    return names


def _targets(node: ast.AST) -> list[ast.expr]:
    if isinstance(node, ast.Assign):
        return [e for t in node.targets for e in (t.elts if isinstance(t, ast.Tuple) else [t])]
    if isinstance(node, ast.AugAssign | ast.AnnAssign):
        return [node.target]
    return []


def state_writes(source: str) -> list[tuple[int, str]]:
    """(line, target) of each write into a model or data reached through `.model`/`.data`."""
    found = set()
    for function in _functions(ast.parse(source)):
        aliases = _aliases(function)
        for node in ast.walk(function):
            for target in _targets(node):
                if not isinstance(target, ast.Subscript | ast.Attribute):
                    continue
                chain, root = [], target
                while isinstance(root, ast.Subscript | ast.Attribute):
                    if isinstance(root, ast.Attribute):
                        chain.append(root.attr)
                    root = root.value
                through = set(chain[1:]) & STATE  # an attribute below the one written
                aliased = isinstance(root, ast.Name) and root.id in aliases and bool(chain)
                if through or aliased:
                    found.add((node.lineno, ast.unparse(target)))
    return sorted(found)


def test_only_the_world_package_writes_a_worlds_model_or_data() -> None:
    offenders = []
    for package in ("twin_cli", "converters", "scenarios"):
        for path in sorted((ROOT / package).rglob("*.py")):
            relative = path.relative_to(ROOT).as_posix()
            if relative.startswith(OWNER):
                continue
            offenders += [f"{relative}:{n}: {t}" for n, t in state_writes(path.read_text())]
    assert offenders == [], "writes outside twin_cli/world/ (add a World method):\n" + "\n".join(
        offenders
    )


@pytest.mark.parametrize(
    ("code", "found"),
    [
        ("def f(world):\n    world.data.ctrl[0] = 1.0\n", [(2, "world.data.ctrl[0]")]),
        (
            "def f(self):\n    self.world.model.opt.timestep = 0.1\n",
            [(2, "self.world.model.opt.timestep")],
        ),
        ("def f(w):\n    m, d = w.model, w.data\n    d.qvel[:] += 1\n", [(3, "d.qvel[:]")]),
        ("def f(world):\n    x = world.data.qpos[0]\n    return x\n", []),  # a read
        ("def f(spec):\n    model = spec.compile()\n    model.opt.timestep = 0.1\n", []),  # its own
    ],
)
def test_the_rule_finds_writes_and_only_writes(code: str, found: list) -> None:
    assert state_writes(code) == found
