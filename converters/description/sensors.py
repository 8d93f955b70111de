"""Gazebo sensors, typed: what a `<sensor>` element says once read (SDF `sensor.sdf` and children).

Part of the neutral description's output: `converters.gazebo.sensors` reads each sensor `Blob`
into one of these records and places it in the built model (a site `sensor:<name>` on the body
that carries its link). Consumers of a running world (`twin_cli.sensors`) simulate them. Units
are SI: angles [rad], ranges [m], rates [Hz]; a `Noise` is in the unit of the value it disturbs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

# Prefix of the MuJoCo site (and camera) that marks a sensor's frame: `sensor:<name>`.
SITE_PREFIX = "sensor:"
# SDF `<noise><type>` values twin simulates (noise.sdf); "none" draws nothing.
NOISE_TYPES = ("none", "gaussian", "gaussian_quantized")
# (part, mjtSensor name) of MuJoCo's own sensors on a sensor's site (`SensorSpec.native_parts`):
# the built model names them `sensor:<name>:<part>`, in this order, so their values are one slice
# of sensordata.
Parts = tuple[tuple[str, str], ...]
# Samples an IMU's native sensors keep in MuJoCo's sensor history (`nsample`), computed at the
# IMU's update period (`interval`): a recorder reads them in one look every few dozen periods.
HISTORY_SAMPLES = 100


@dataclass(frozen=True)
class Noise:
    """SDF `<noise>`: additive Gaussian noise with a constant bias drawn once per sensor.

    As Gazebo's `GaussianNoiseModel`: the bias is drawn from N(bias_mean, bias_stddev) when the
    sensor starts and its sign flipped with probability ½; every reading then gets
    bias + N(mean, stddev); `gaussian_quantized` rounds the result to a multiple of `precision`.
    """

    type: str = "none"
    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0
    precision: float = 0.0

    @property
    def active(self) -> bool:
        return self.type != "none"

    def summary(self) -> str:
        """One phrase for reports: its type, mean and stddev, or "none"."""
        if not self.active:
            return "none"
        return f"{self.type} mean {self.mean:g} stddev {self.stddev:g}"


def _stddevs(noises: tuple[Noise, ...]) -> str:
    return ", ".join(f"{n.stddev:g}" for n in noises if n.active) or "none"


NO_NOISE = Noise()
NO_NOISE3 = (NO_NOISE, NO_NOISE, NO_NOISE)


@dataclass(frozen=True)
class SensorSpec:
    """What every sensor has (SDF `<sensor>`), before its type's own values.

    Attributes:
        name: the sensor's name (unique in the robot).
        type: Gazebo's `type` attribute as written (`ray`, `gpu_lidar`, `imu`, ...).
        link: the description link it is attached to.
        pose: x y z [m] roll pitch yaw [rad] of the sensor in the link frame.
        update_rate: [Hz]; 0 means every physics step (Gazebo: "as fast as possible").
        always_on: SDF `<always_on>`.
        topic: where Gazebo/gazebo_ros would publish it (`<topic>`, a plugin's topic), or "".
        frame_id: the frame named in its ROS plugin (`frameName`, `frame_name`), else the link.
        where: file and element it was written in, for reports.
        body: the MuJoCo body carrying the sensor's site (the link's body after lumping).

    Class attributes: `native_parts`, the MuJoCo sensors its site carries, (part, mjtSensor
    name) in sensordata order (none by default); `native_history`, whether MuJoCo computes them
    only at its update period and keeps `HISTORY_SAMPLES` of them. A kind says in `details`
    what it became, for the conversion report.
    """

    native_parts: ClassVar[Parts] = ()
    native_history: ClassVar[bool] = False

    name: str
    type: str
    link: str
    pose: tuple[float, float, float, float, float, float]
    update_rate: float
    always_on: bool
    topic: str
    frame_id: str
    where: str
    body: str

    @property
    def site(self) -> str:
        """The MuJoCo site at the sensor's frame (prefixed with `<entity>/` once spawned)."""
        return SITE_PREFIX + self.name

    def details(self) -> str:
        """What the sensor became, its values and noise, for the conversion report."""
        return ""


@dataclass(frozen=True)
class ImuSpec(SensorSpec):
    """SDF `<imu>`: noise per axis of angular velocity [rad/s] and linear acceleration [m/s²]."""

    angular_velocity_noise: tuple[Noise, Noise, Noise] = NO_NOISE3
    linear_acceleration_noise: tuple[Noise, Noise, Noise] = NO_NOISE3
    enable_orientation: bool = True
    native_parts: ClassVar[Parts] = (
        ("quat", "mjSENS_FRAMEQUAT"),
        ("gyro", "mjSENS_GYRO"),
        ("accel", "mjSENS_ACCELEROMETER"),
    )
    native_history: ClassVar[bool] = True

    def details(self) -> str:
        noisy = _stddevs(self.angular_velocity_noise + self.linear_acceleration_noise)
        return f"orientation, angular velocity, specific force; noise stddev {noisy}"


@dataclass(frozen=True)
class RaySpec(SensorSpec):
    """SDF `<ray>`/`<lidar>`: a scan of `samples × resolution` rays per direction.

    Angles [rad] about the sensor's z (horizontal) and y (vertical) axes; ranges [m].
    `range_resolution` is kept for reports; Gazebo does not quantise ranges by it either.
    """

    horizontal_samples: int = 640
    horizontal_resolution: float = 1.0
    horizontal_min_angle: float = 0.0
    horizontal_max_angle: float = 0.0
    vertical_samples: int = 1
    vertical_resolution: float = 1.0
    vertical_min_angle: float = 0.0
    vertical_max_angle: float = 0.0
    range_min: float = 0.0
    range_max: float = 0.0
    range_resolution: float = 0.0
    noise: Noise = NO_NOISE

    @property
    def horizontal_rays(self) -> int:
        return max(1, round(self.horizontal_samples * self.horizontal_resolution))

    @property
    def vertical_rays(self) -> int:
        return max(1, round(self.vertical_samples * self.vertical_resolution))

    def details(self) -> str:
        return (
            f"{self.horizontal_rays}×{self.vertical_rays} MuJoCo rays, "
            f"{self.horizontal_min_angle:g}..{self.horizontal_max_angle:g} rad, "
            f"range {self.range_min:g}..{self.range_max:g} m; noise {self.noise.summary()}"
        )


@dataclass(frozen=True)
class ContactSpec(SensorSpec):
    """SDF `<contact>` (and the gazebo_ros bumper): contacts on the link's collision geoms.

    `collision` is the `<contact><collision>` name as written; `geoms` the MuJoCo geoms built
    from the link's collisions, which the sensor watches.
    """

    collision: str = ""
    geoms: tuple[str, ...] = ()

    def details(self) -> str:
        return f"contacts of {len(self.geoms)} collision geoms"


@dataclass(frozen=True)
class ForceTorqueSpec(SensorSpec):
    """SDF `<force_torque>` on a joint: the wrench the joint transmits, at the joint's origin.

    `frame` is `child`, `parent` or `sensor` (the frame the wrench is expressed in);
    `measure_direction` is `child_to_parent` (Gazebo's default: what the child applies on the
    parent) or `parent_to_child`. `child_body`/`parent_body` are the joint's MuJoCo bodies.
    `force_noise` [N] and `torque_noise` [N m] are per axis of the reported frame (SDF
    `<force><x><noise>`, ..., or a gazebo_ros F/T plugin's `<gaussianNoise>` on all six).
    """

    joint: str = ""
    frame: str = "child"
    measure_direction: str = "child_to_parent"
    child_body: str = ""
    parent_body: str = ""
    force_noise: tuple[Noise, Noise, Noise] = NO_NOISE3
    torque_noise: tuple[Noise, Noise, Noise] = NO_NOISE3
    native_parts: ClassVar[Parts] = (("force", "mjSENS_FORCE"), ("torque", "mjSENS_TORQUE"))

    def details(self) -> str:
        noisy = _stddevs(self.force_noise + self.torque_noise)
        return (
            f"wrench of joint '{self.joint}' in the {self.frame} frame, "
            f"{self.measure_direction}; noise stddev {noisy}"
        )


@dataclass(frozen=True)
class CameraSpec(SensorSpec):
    """SDF `<camera>`: image size [px], horizontal field of view [rad], clip planes [m].

    `depth` is True for `depth`/`depth_camera`/`rgbd_camera` sensors. The camera looks along
    the sensor's +x with +z up (Gazebo's convention).
    """

    width: int = 320
    height: int = 240
    horizontal_fov: float = 1.047
    near: float = 0.1
    far: float = 100.0
    image_format: str = "R8G8B8"
    depth: bool = False
    noise: Noise = NO_NOISE

    def details(self) -> str:
        kind = "depth" if self.depth else "colour"
        return (
            f"{kind} image {self.width}×{self.height}, hfov {self.horizontal_fov:g} rad, "
            f"clip {self.near:g}..{self.far:g} m (offscreen rendering: needs MUJOCO_GL=egl "
            "or osmesa; image noise not simulated)"
        )
