"""`twin validate`'s zero-gravity check on a robot whose controller pushes a constant force: a
gz-sim JointPositionController's `cmd_offset` moves the held bar off its target (to about
offset/p rad) without gravity, in Gazebo as in twin, so the check fails and its hint names the
joint and the force; without an offset the bar stays put and the check passes."""

from __future__ import annotations

from pathlib import Path

import pytest
from models import hinged_bar

from twin_cli.validate.runner import validate

PID = (
    '<plugin filename="gz-sim-joint-position-controller-system" '
    'name="gz::sim::systems::JointPositionController"><joint_name>hinge</joint_name>'
    "<p_gain>100</p_gain><d_gain>2</d_gain>{tags}</plugin>"
)


@pytest.mark.parametrize(
    ("tags", "push"),
    [
        ("<cmd_offset>3</cmd_offset>", "'hinge' 3 N m"),  # beside gz-math's integral
        ("<cmd_offset>-2</cmd_offset><i_gain>0</i_gain>", "'hinge' -2 N m"),  # the servo's bias
        ("<i_gain>0</i_gain>", None),
    ],
)
def test_zero_gravity_names_a_controllers_constant_force(
    tmp_path: Path, tags: str, push: str | None
) -> None:
    path = tmp_path / "bar.urdf"
    path.write_text(hinged_bar(PID.format(tags=tags)))
    (result,) = validate(path, only=["zero_gravity"]).results
    hints = " ".join(result.hints)
    if push is None:
        assert result.status.value == "pass" and "constant forces" not in hints, (
            result.status,
            hints,
        )
    else:
        assert result.status.value == "fail", f"{result.status}: {result.measured}"
        assert f"its controllers push constant forces ({push})" in hints, hints
