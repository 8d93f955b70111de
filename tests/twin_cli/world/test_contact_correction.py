"""ODE's contact_max_correcting_vel: read from an SDF world's <physics> and shown by physics()."""

from __future__ import annotations

from pathlib import Path

import pytest

from converters.errors import ConversionError
from twin_cli.world import World
from twin_cli.world.sdf_world import world_from_sdf

WORLD = """<?xml version="1.0"?>
<sdf version="1.8"><world name="w"><physics type="ode"><max_step_size>0.001</max_step_size>
<ode><constraints><contact_max_correcting_vel>{value}</contact_max_correcting_vel></constraints>
</ode></physics></world></sdf>"""


def test_the_world_files_correcting_velocity_is_reported(tmp_path: Path) -> None:
    path = tmp_path / "w.world"
    path.write_text(WORLD.format(value="2.5"))
    assert world_from_sdf(path).physics()["contact_max_correcting_vel"] == 2.5, "[m/s]"


def test_the_default_is_odes_100_m_per_s() -> None:
    assert World().physics()["contact_max_correcting_vel"] == 100.0, "physics.sdf default [m/s]"


def test_a_negative_correcting_velocity_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "w.world"
    path.write_text(WORLD.format(value="-1"))
    where = r"w\.world:3: <contact_max_correcting_vel>: -1\.0 m/s; give a speed >= 0"
    with pytest.raises(ConversionError, match=where):
        world_from_sdf(path)
