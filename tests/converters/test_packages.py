"""The package resolver: search order, hyphenated packages, model://, and its failure message."""

from __future__ import annotations

from pathlib import Path

import pytest

from converters.errors import PackageNotFoundError, ResourceNotFoundError
from converters.resources.packages import PackageResolver


def _package(root: Path, directory: str, name: str | None = None) -> Path:
    path = root / directory
    (path / "meshes").mkdir(parents=True)
    (path / "meshes" / "m.stl").write_text("solid x\nendsolid x\n")
    if name is not None:
        (path / "package.xml").write_text(f"<package><name>{name}</name></package>")
    return path


def test_explicit_package_option_wins_over_ros_package_path(tmp_path: Path) -> None:
    first = _package(tmp_path / "a", "pkg")
    second = _package(tmp_path / "b", "pkg")
    resolver = PackageResolver.create(
        None, {"pkg": second}, env={"ROS_PACKAGE_PATH": str(first.parent)}
    )
    assert resolver.find_package("pkg") == second.resolve()
    assert (
        PackageResolver.create(None, env={"ROS_PACKAGE_PATH": str(first.parent)}).find_package(
            "pkg"
        )
        == first
    )


def test_ament_prefix_and_gazebo_model_paths(tmp_path: Path) -> None:
    shared = _package(tmp_path / "prefix" / "share", "ament_pkg")
    model = _package(tmp_path / "models", "cart")
    resolver = PackageResolver.create(
        None,
        env={
            "AMENT_PREFIX_PATH": str(tmp_path / "prefix"),
            "GZ_SIM_RESOURCE_PATH": str(tmp_path / "models"),
        },
    )
    assert resolver.find_package("ament_pkg") == shared
    path = resolver.resolve("model://cart/meshes/m.stl", base_dir=tmp_path, element="test")
    assert path == model / "meshes" / "m.stl"


def test_directory_above_the_input_whose_package_xml_names_it(tmp_path: Path) -> None:
    package = _package(tmp_path, "checkout_dir", name="real_name")
    (package / "urdf").mkdir()
    robot = package / "urdf" / "r.urdf"
    robot.write_text("<robot/>")
    resolver = PackageResolver.create(robot, env={})
    path = resolver.resolve("package://real_name/meshes/m.stl", base_dir=robot.parent, element="x")
    assert path == package.resolve() / "meshes" / "m.stl"
    relative = resolver.resolve("../meshes/m.stl", base_dir=robot.parent, element="x")
    assert relative == package.resolve() / "meshes" / "m.stl"
    assert resolver.resolve(f"file://{relative}", base_dir=tmp_path, element="x") == relative


def test_unknown_package_names_uri_element_and_every_place_tried(tmp_path: Path) -> None:
    resolver = PackageResolver.create(None, env={"ROS_PACKAGE_PATH": str(tmp_path)})
    with pytest.raises(PackageNotFoundError) as caught:
        resolver.resolve("package://ghost/m.stl", base_dir=tmp_path, element="link 'a' <mesh>")
    message = str(caught.value)
    assert "package://ghost/m.stl" in message and "link 'a' <mesh>" in message
    assert str(tmp_path / "ghost") in message, "the places tried must be listed"


def test_missing_file_in_a_found_package(tmp_path: Path) -> None:
    _package(tmp_path, "pkg")
    resolver = PackageResolver.create(None, env={"ROS_PACKAGE_PATH": str(tmp_path)})
    with pytest.raises(ResourceNotFoundError, match="nothere.stl"):
        resolver.resolve("package://pkg/nothere.stl", base_dir=tmp_path, element="x")


def test_corpus_hyphenated_package_with_nested_robots(corpus_root: Path) -> None:
    resolver = PackageResolver.create(None, env={"ROS_PACKAGE_PATH": str(corpus_root / "packages")})
    uri = "package://example-robot-data/robots/solo_description/meshes/stl/with_foot/solo_foot.stl"
    assert resolver.resolve(uri, base_dir=corpus_root, element="x").is_file()
