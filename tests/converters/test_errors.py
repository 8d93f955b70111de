"""Every converter-core error builds its message from the facts: what, where, and the fix."""

from __future__ import annotations

import pytest

from converters import errors

CASES = [
    (
        errors.PackageNotFoundError("pkg", "package://pkg/a.stl", "link 'l' <mesh>", ["/x/pkg"]),
        ["'pkg'", "package://pkg/a.stl", "link 'l'", "/x/pkg", "--package pkg=PATH"],
    ),
    (
        errors.ResourceNotFoundError("meshes/a.stl", "link 'l' <mesh>", "/r/meshes/a.stl"),
        ["meshes/a.stl", "link 'l'", "/r/meshes/a.stl", "fix"],
    ),
    (
        errors.XacroError("r.xacro", "Undefined substitution argument X"),
        ["r.xacro", "Undefined substitution argument X", "--arg"],
    ),
    (errors.MalformedXMLError("r.urdf", 3, 7, "mismatched tag"), ["r.urdf:3:7", "mismatched tag"]),
    (
        errors.URDFStructureError(
            "r.urdf", "joint 'j'", "child link 'x' does not exist", "use one of the links: a, b"
        ),
        ["r.urdf", "joint 'j'", "a, b"],
    ),
    (
        errors.BadNumberError("r.urdf", "link 'a' <mass>", "value", "heavy", "a number"),
        ["r.urdf", "link 'a' <mass>", "'heavy'", "a number"],
    ),
    (
        errors.InertiaError("r.urdf", "hatch", "not positive definite", "mass=1 ixx=0"),
        ["r.urdf", "link 'hatch'", "not positive definite", "mass=1", "--repair-inertia"],
    ),
    (errors.MeshError("/m.dae", "l", "holds no triangles"), ["/m.dae", "link 'l'", "triangles"]),
]


@pytest.mark.parametrize(("error", "needles"), CASES, ids=[type(c[0]).__name__ for c in CASES])
def test_error_message_names_what_where_and_fix(error: Exception, needles: list[str]) -> None:
    assert isinstance(error, errors.ConversionError), "must reach the CLI error boundary"
    for needle in needles:
        assert needle in str(error), f"{needle!r} missing from {error}"
