"""Gazebo's own URDF parse by default: what sdformat drops is dropped, reported, and opt-in."""

from __future__ import annotations

from pathlib import Path

import pytest
from corpus_registry import needs_corpus
from models import write_urdf

from converters.collision.plan import CollisionSettings
from converters.errors import InertiaError
from converters.gazebo.contact import friction_priority
from converters.mjcf.builder import ConvertOptions
from converters.pipeline import convert_full
from converters.report import Outcome

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)
BOX = '<geometry><box size="0.1 0.1 0.1"/></geometry>'
INLINE = (
    "<surface><friction><ode><mu>0.2</mu><mu2>0.2</mu2></ode></friction>"
    "<contact><ode><kp>1e5</kp></ode></contact></surface>"
)


def _robot(link_body: str, gazebo: str = "") -> str:
    return f'<robot name="r"><link name="base">{INERTIAL}{link_body}</link>{gazebo}</robot>'


def _mu(done, geom: str) -> float:
    return float(done.spec.compile().geom(geom).friction[0])


def test_inline_surface_is_ignored_as_gazebo_ignores_it(tmp_path: Path) -> None:
    path = write_urdf(tmp_path, _robot(f"<collision>{BOX}{INLINE}</collision>"))
    done = convert_full(path)
    model = done.spec.compile()
    geom = model.geom("base_collision_0")
    assert geom.friction[0] == pytest.approx(1.0), "Gazebo simulates SDF's default μ"
    assert geom.priority[0] == friction_priority(1.0)
    ignored = [e for e in done.report.of(Outcome.IGNORED) if "<surface>" in e.subject]
    assert ignored and "--as-written" in ignored[0].detail, "reported with the opt-in"


def test_as_written_applies_the_inline_surface(tmp_path: Path) -> None:
    path = write_urdf(tmp_path, _robot(f"<collision>{BOX}{INLINE}</collision>"))
    done = convert_full(path, options=ConvertOptions(as_written=True))
    assert _mu(done, "base_collision_0") == pytest.approx(0.2), "the file's μ"


def test_a_named_collision_gets_none_of_its_links_gazebo_values(tmp_path: Path) -> None:
    body = f'<collision name="shell">{BOX}</collision><collision>{BOX}</collision>'
    gazebo = '<gazebo reference="base"><mu1>0.3</mu1><mu2>0.3</mu2></gazebo>'
    path = write_urdf(tmp_path, _robot(body, gazebo))
    done = convert_full(path)
    assert _mu(done, "base_collision_0") == pytest.approx(1.0), "named: Gazebo's default μ"
    assert _mu(done, "base_collision_1") == pytest.approx(0.3), "unnamed: the link's μ"
    ignored = [e.subject for e in done.report.of(Outcome.IGNORED)]
    assert "link 'base' collision 0" in ignored, ignored
    written = convert_full(path, options=ConvertOptions(as_written=True))
    assert _mu(written, "base_collision_0") == pytest.approx(0.3), "as written: both"


def test_a_moving_link_without_inertial_names_what_gazebo_would_drop(tmp_path: Path) -> None:
    limit = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    text = (
        f'<robot name="r"><link name="base">{INERTIAL}</link><link name="arm"/>'
        f'<link name="hand">{INERTIAL}</link><link name="base_only">{INERTIAL}</link>'
        f'<joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>{limit}</joint>'
        f'<joint name="j2" type="revolute"><parent link="arm"/><child link="hand"/>{limit}'
        '</joint><joint name="j3" type="fixed"><parent link="base"/><child link="base_only"/>'
        "</joint></robot>"
    )
    with pytest.raises(InertiaError) as caught:
        convert_full(write_urdf(tmp_path, text))
    message = str(caught.value)
    assert "link 'arm'" in message and "drop arm, hand" in message, message
    assert "base_only" not in message, "only the link's own subtree"


@needs_corpus
def test_robotiq_fingertips_get_what_gazebo_simulates_unless_as_written() -> None:
    """robotiq_2f_85 writes μ 1e5, kp 1e5 inline in its fingertip collisions; Gazebo ignores
    them (μ 1, kp 1e12 there), and so does twin unless asked."""
    from corpus_registry import CORPUS, PACKAGES_ROOT, package_paths

    from converters.gazebo.contact import CONTACT_MU_MAX

    robot = CORPUS["robotiq_2f_85"]
    path = PACKAGES_ROOT / robot["entry"]
    inputs = {"args": robot["xacro_args"], "package_paths": package_paths(robot)}
    mesh = {"collision": CollisionSettings(mode="hull")}
    gazebo = convert_full(path, **inputs, options=ConvertOptions(**mesh)).spec.compile()
    written = convert_full(path, **inputs, options=ConvertOptions(**mesh, as_written=True))
    written_model = written.spec.compile()
    for side in ("left", "right"):
        name = f"robotiq_85_{side}_finger_tip_link_collision_0"
        assert gazebo.geom(name).friction[0] == pytest.approx(1.0), f"{side}: Gazebo's μ"
        # As written: μ 1e5, which twin caps (MuJoCo's contact sinks under a larger μ).
        mu = written_model.geom(name).friction[0]
        assert mu == pytest.approx(CONTACT_MU_MAX), f"{side}: as written, capped"
