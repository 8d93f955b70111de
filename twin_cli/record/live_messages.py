"""The live messages of one layout (`/clock`, `/tf`, joint states, odometry), refilled per sample.

A recording of an unthrottled world makes thousands of samples per wall second, and building a
fresh rosbags object for every header, vector and quaternion of every sample cost the encoder
two thirds of its time (~190 of ~290 µs per humanoid sample). So the message objects of a layout
are built once, all headers share one stamp, and each sample only writes its numbers into them:
the relative link poses of every entity in one vectorised pass, then plain float assignments.
The objects are reused, so a sink must encode a message within `write` (both sinks do).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twin_cli.record import messages as ros
from twin_cli.record.layout import WORLD_FRAME, EntityLayout, Layout
from twin_cli.record.sampler import Sample
from twin_cli.record.topics import CLOCK, TF, Message, transform_stamped
from twin_cli.world.pose import rotate

# conj(q) ⊗ r as a matrix product M(q) r: M's entries are q's components, permuted and signed.
_CONJ_LEFT_INDEX = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_CONJ_LEFT_SIGN = np.array(
    [[1.0, 1.0, 1.0, 1.0], [-1.0, 1.0, 1.0, -1.0], [-1.0, -1.0, 1.0, 1.0], [-1.0, 1.0, -1.0, 1.0]]
)

_ORIGIN, _IDENTITY = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)  # a transform before the first fill


def relative_poses(
    xpos: np.ndarray, xquat: np.ndarray, xmat: np.ndarray, bodies: np.ndarray, parents: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each body's pose in its parent's frame: p = R_parentᵀ (x − x_parent), q = q̄_parent ⊗ q.

    Args: world positions (nbody×3), quaternions w,x,y,z (nbody×4) and rotation matrices
    (nbody×9) of every body; the bodies and their parents (index arrays of one length).
    """
    offset = (xpos[bodies] - xpos[parents])[:, None, :]
    pos = (offset @ xmat[parents].reshape(-1, 3, 3))[:, 0, :]  # row vector · R = (Rᵀ v)ᵀ
    left = xquat[parents][:, _CONJ_LEFT_INDEX] * _CONJ_LEFT_SIGN
    quat = (left @ xquat[bodies][:, :, None])[:, :, 0]
    return pos, quat


class LiveMessages:
    """The reusable live messages of one layout; `fill` writes a sample into them."""

    def __init__(self, layout: Layout) -> None:
        T = ros.types()
        self.layout = layout
        self._stamp = T["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
        self._clock = T[ros.CLOCK](clock=self._stamp)
        entities = layout.entities
        self._bodies = np.concatenate([e.moving for e in entities] or [np.zeros(0, int)])
        self._parents = np.concatenate([e.moving_parents for e in entities] or [np.zeros(0, int)])
        frames = layout.body_frames
        transforms = [
            transform_stamped(self._stamp, frames[p], frames[b], _ORIGIN, _IDENTITY)
            for b, p in zip(self._bodies.tolist(), self._parents.tolist(), strict=True)
        ]
        self._translations = [t.transform.translation for t in transforms]
        self._rotations = [t.transform.rotation for t in transforms]
        self._tf = T[ros.TF](transforms=transforms)
        self._joints = [_JointStates(T, layout, e, self._stamp) for e in entities]
        self._odometry = [_Odometry(T, e, self._stamp) for e in entities if e.free_qpos >= 0]

    def fill(
        self, sample: Sample, xpos: np.ndarray, xquat: np.ndarray, xmat: np.ndarray
    ) -> list[Message]:
        """The sample's messages (the same objects as the last call's, refilled)."""
        t = sample.time
        self._stamp.sec, self._stamp.nanosec = divmod(ros.nanoseconds(t), 1_000_000_000)
        pos, quat = relative_poses(xpos, xquat, xmat, self._bodies, self._parents)
        for v, xyz in zip(self._translations, pos.tolist(), strict=True):
            v.x, v.y, v.z = xyz
        for q, wxyz in zip(self._rotations, quat.tolist(), strict=True):
            q.w, q.x, q.y, q.z = wxyz
        out = [
            Message(CLOCK.name, ros.CLOCK, t, self._clock),
            Message(TF.name, ros.TF, t, self._tf),
        ]
        out += [joints.fill(sample) for joints in self._joints]
        out += [odometry.fill(sample) for odometry in self._odometry]
        return out


class _JointStates:
    """`/<entity>/joint_states`: position, velocity and actuator effort, as `World.joint_states`
    (a ball joint: its rotation angle and angular speed, no effort)."""

    def __init__(self, T: Any, layout: Layout, e: EntityLayout, stamp: Any) -> None:
        model = layout.model
        self._qpos = model.jnt_qposadr[e.joint_ids]
        self._dofs = model.jnt_dofadr[e.joint_ids]
        self._balls = e.ball_joints
        self._topic = f"/{e.name}/joint_states"
        self._message = T[ros.JOINT_STATE](
            header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=""),
            name=list(e.joint_names),
            position=np.zeros(0),
            velocity=np.zeros(0),
            effort=np.zeros(0),
        )

    def fill(self, sample: Sample) -> Message:
        m, qa, da = self._message, self._qpos, self._dofs
        m.position, m.velocity = sample.qpos[qa], sample.qvel[da]
        m.effort = sample.qfrc_actuator[da]
        for k in self._balls:
            m.position[k] = 2.0 * np.arccos(min(1.0, abs(float(sample.qpos[qa[k]]))))
            m.velocity[k] = np.linalg.norm(sample.qvel[da[k] : da[k] + 3])
            m.effort[k] = 0.0
        return Message(self._topic, ros.JOINT_STATE, sample.time, m)


class _Odometry:
    """`/<entity>/odom` of a floating base: its pose in the world and its twist in its own frame
    (MuJoCo's free-joint linear velocity is global and its angular velocity local)."""

    def __init__(self, T: Any, e: EntityLayout, stamp: Any) -> None:
        self._qpos, self._dof = e.free_qpos, e.free_dof
        self._topic = f"/{e.name}/odom"
        vector, zeros = T["geometry_msgs/msg/Vector3"], np.zeros(36)
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=0.0, y=0.0, z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        )
        twist = T["geometry_msgs/msg/Twist"](
            linear=vector(x=0.0, y=0.0, z=0.0), angular=vector(x=0.0, y=0.0, z=0.0)
        )
        self._pose, self._twist = pose, twist
        self._message = T[ros.ODOMETRY](
            header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=WORLD_FRAME),
            child_frame_id=e.root_frame,
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=zeros),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=zeros),
        )

    def fill(self, sample: Sample) -> Message:
        x, y, z, qw, qx, qy, qz = sample.qpos[self._qpos : self._qpos + 7].tolist()
        vx, vy, vz, wx, wy, wz = sample.qvel[self._dof : self._dof + 6].tolist()
        p, o = self._pose.position, self._pose.orientation
        p.x, p.y, p.z, o.w, o.x, o.y, o.z = x, y, z, qw, qx, qy, qz
        linear, angular = self._twist.linear, self._twist.angular
        linear.x, linear.y, linear.z = rotate((qw, -qx, -qy, -qz), (vx, vy, vz))  # Rᵀ v
        angular.x, angular.y, angular.z = wx, wy, wz
        return Message(self._topic, ros.ODOMETRY, sample.time, self._message)
