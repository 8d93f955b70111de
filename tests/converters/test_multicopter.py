"""gz-sim's MulticopterMotorModel read and mapped: parameters, actuators, and their wrench.

Oracle: the plugin's definitions, with ω the rotor speed: thrust k·ω² along the rotor link's z,
yaw moment −dir·momentConstant·thrust about it (dir +1 ccw, −1 cw), rotor drag −|ω|·C·v⊥.
The wrench is read from MuJoCo (qfrc_actuator of the free joint) at steady activation.
"""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest

from converters.errors import GazeboTagError
from converters.pipeline import convert_text

K, KM, CD = 8.54858e-06, 0.016, 8.06428e-05  # [N s²/rad²], [m], [N s²/rad/m]
TILT = 0.3  # [rad] roll of the rotor link, so thrust is not along the world's z


def _plugin(filename: str = "gz-sim-multicopter-motor-model-system", **values: str) -> str:
    params = {
        "jointName": "rotor_joint",
        "linkName": "rotor",
        "turningDirection": "cw",
        "timeConstantUp": "0.01",
        "timeConstantDown": "0.03",
        "maxRotVelocity": "900",
        "motorConstant": str(K),
        "momentConstant": str(KM),
        "rotorDragCoefficient": str(CD),
        "rollingMomentCoefficient": "1e-6",
        "motorNumber": "2",
        "rotorVelocitySlowdownSim": "5",
        "motorType": "velocity",
    }
    params.update(values)
    body = "".join(f"<{k}>{v}</{k}>" for k, v in params.items() if v != "-")
    return f'<plugin filename="{filename}" name="motor">{body}</plugin>'


def _model(plugins: str) -> str:
    return f"""<sdf version="1.9"><model name="m"><link name="base"><inertial><mass>1</mass>
<inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
<link name="rotor"><pose>0.2 0.1 0.05 {TILT} 0 0</pose><inertial><mass>0.01</mass>
<inertia><ixx>1e-5</ixx><iyy>1e-5</iyy><izz>1e-5</izz></inertia></inertial></link>
<joint name="rotor_joint" type="revolute"><parent>base</parent><child>rotor</child>
<axis><xyz>0 0 1</xyz></axis></joint>{plugins}</model></sdf>"""


def test_parameters_become_site_actuators_and_a_velocity_only_record() -> None:
    done = convert_text(_model(_plugin()))
    rotor = next(p for p in done.plugins if type(p).__name__ == "Rotor")
    assert (rotor.direction, rotor.motor_number, rotor.slowdown) == (-1, 2, 5.0)
    assert (rotor.time_constant_up, rotor.time_constant_down, rotor.max_rot_velocity) == (
        0.01,
        0.03,
        900.0,
    )
    model = done.spec.compile()
    thrust = model.actuator("rotor_joint:thrust")
    np.testing.assert_allclose(thrust.gear, [0, 0, 1, 0, 0, KM])  # cw: +momentConstant
    assert thrust.gainprm[0] == K and thrust.dyntype == mujoco.mjtDyn.mjDYN_FILTEREXACT
    np.testing.assert_allclose(thrust.dynprm[:3], [0.01, 0.01, 0.03])
    assert model.actuator("rotor_joint:drag_x").gainprm[2] == -CD
    spin = model.actuator("rotor_joint")
    assert spin.gear[0] == -5.0 and model.site("rotor:rotor_joint").bodyid == model.body("base").id
    record = json.loads(done.spec.text("control").data)["rotor_joint"]
    assert record["modes"] == ["velocity"] and record["velocity_limit"] == 900.0


def _wrench(velocity: tuple[float, float, float], omega: float) -> np.ndarray:
    """The rotor actuators' generalized force on the free joint at steady speed ω [rad/s]."""
    model = convert_text(_model(_plugin())).spec.compile()
    data = mujoco.MjData(model)
    data.qvel[:3] = velocity
    for a in range(model.nu):
        name = model.actuator(a).name
        value = omega * abs(omega) if name.endswith(":thrust") else abs(omega)
        if name.startswith("rotor_joint:"):
            data.act[model.actuator_actadr[a]] = data.ctrl[a] = value
    mujoco.mj_forward(model, data)
    return np.array(data.qfrc_actuator[:6])


def test_thrust_and_yaw_moment_along_the_tilted_rotor_axis() -> None:
    omega = 600.0
    axis = np.array([0.0, -math.sin(TILT), math.cos(TILT)])  # rotor z after roll TILT
    wrench = _wrench((0.0, 0.0, 0.0), omega)
    thrust = K * omega**2
    np.testing.assert_allclose(wrench[:3], thrust * axis, atol=1e-12)
    offset = np.array([0.2, 0.1, 0.05])
    moment = np.cross(offset, thrust * axis) + KM * thrust * axis  # cw: +momentConstant·T
    np.testing.assert_allclose(wrench[3:], moment, atol=1e-12)  # base frame = world here


def test_rotor_drag_opposes_the_velocity_across_the_axis() -> None:
    omega, v = 500.0, np.array([2.0, 0.0, 1.0])
    axis = np.array([0.0, -math.sin(TILT), math.cos(TILT)])
    across = v - v.dot(axis) * axis
    drag = _wrench(tuple(v), omega)[:3] - _wrench((0.0, 0.0, 0.0), omega)[:3]
    np.testing.assert_allclose(drag, -omega * CD * across, atol=1e-12)


@pytest.mark.parametrize(
    ("values", "tag"),
    [
        ({"turningDirection": "left"}, "turningDirection"),
        ({"motorType": "force"}, "motorType"),
        ({"motorConstant": "lots"}, "motorConstant"),
        ({"jointName": "nope"}, "jointName"),
    ],
)
def test_bad_parameters_are_refused_with_the_tag(values: dict, tag: str) -> None:
    with pytest.raises(GazeboTagError, match=tag):
        convert_text(_model(_plugin(**values)))


def test_a_motor_model_without_link_name_is_reported_not_run_as_gz_sim_does() -> None:
    done = convert_text(_model(_plugin(linkName="-")))
    assert not [p for p in done.plugins if type(p).__name__ == "Rotor"]
    details = [e.detail for e in done.report.entries if e.outcome.name == "IGNORED"]
    assert any("no <linkName>, so gz-sim does not start it" in d for d in details)
    records = json.loads(done.spec.text("control").data)
    assert {r["source"] for r in records.values()} == {"passive"}, "no rotor actuators"


def test_classic_plugin_mapped_lift_drag_and_hydrodynamics_reported_with_needs() -> None:
    others = (
        '<plugin filename="gz-sim-lift-drag-system" name="gz::sim::systems::LiftDrag"/>'
        '<plugin filename="gz-sim-hydrodynamics-system" name="gz::sim::systems::Hydrodynamics"/>'
    )
    done = convert_text(_model(_plugin("libgazebo_motor_model.so") + others))
    entries = [e for e in done.report.entries if e.tag == "plugin"]
    ignored = [e.detail for e in entries if e.outcome.name == "IGNORED"]
    assert any("LiftDrag: not run; needs" in d for d in ignored)
    assert any("Hydrodynamics: not run; needs" in d for d in ignored)
    mapped = [e.detail for e in entries if e.outcome.name == "MAPPED"]
    assert any("rolling moment not applied" in d for d in mapped)
    assert done.spec.compile().actuator("rotor_joint:thrust").gear[5] == pytest.approx(KM)
