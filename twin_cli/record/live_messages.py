"""The live messages of one layout (`/clock`, `/tf`, joint states, odometry), refilled per sample.

A recording of an unthrottled world makes thousands of samples per wall second, and building a
fresh rosbags object for every header, vector and quaternion of every sample cost the encoder
two thirds of its time (~190 of ~290 µs per humanoid sample). So the message objects of a layout
are built once, all headers share one stamp, and each sample only writes its numbers into them.
The numbers of a whole batch of samples (the encoder reads up to 256 at a time) are computed in
one vectorised pass first: relative link poses, joint states, odometry twists. The objects are
reused, so a sink must encode a message within `write` (both sinks do), and each message carries
its `messages.Reencoder`, which serializes the refilled object without re-measuring it.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from twin_cli.names import namespace
from twin_cli.record import messages as ros
from twin_cli.record.layout import EntityLayout, Layout, MovingEdges
from twin_cli.record.sampler import Samples
from twin_cli.record.topics import CLOCK, TF, Message, moves, transform_stamped

# conj(q) ⊗ r as a matrix product M(q) r: M's entries are q's components, permuted and signed.
_CONJ_LEFT_INDEX = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_CONJ_LEFT_SIGN = np.array(
    [[1.0, 1.0, 1.0, 1.0], [-1.0, 1.0, 1.0, -1.0], [-1.0, -1.0, 1.0, 1.0], [-1.0, 1.0, -1.0, 1.0]]
)

_ORIGIN, _IDENTITY = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)  # a transform before the first fill
_IDENTITY_QUAT = np.array(_IDENTITY)


def relative_poses(
    xpos: np.ndarray, xquat: np.ndarray, xmat: np.ndarray, bodies: np.ndarray, parents: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each body's pose in its parent's frame: p = R_parentᵀ (x − x_parent), q = q̄_parent ⊗ q.

    Args: world positions (…×nbody×3), quaternions w,x,y,z (…×nbody×4) and rotation matrices
    (…×nbody×9) of every body, with any leading (batch) axes; the bodies and their parents
    (index arrays of one length). Returns positions (…×m×3) and quaternions (…×m×4).
    """
    offset = (xpos[..., bodies, :] - xpos[..., parents, :])[..., None, :]
    rotations = xmat[..., parents, :].reshape(*xmat.shape[:-2], len(parents), 3, 3)
    pos = (offset @ rotations)[..., 0, :]  # row vector · R = (Rᵀ v)ᵀ
    left = xquat[..., parents, :][..., _CONJ_LEFT_INDEX] * _CONJ_LEFT_SIGN
    quat = (left @ xquat[..., bodies, :, None])[..., 0]
    return pos, quat


def frame_poses(
    pos: np.ndarray, quat: np.ndarray, edges: MovingEdges
) -> tuple[np.ndarray, np.ndarray]:
    """Child frames in parent frames from child bodies in parent bodies (…×m×3, …×m×4): each
    frame's constant pose in its body on either side, O_parent⁻¹ · pose · O_child, applied only
    to the edges whose frames are not their bodies' (lumped links, the odometry frame)."""
    child = np.flatnonzero(_not_identity(edges.child_pos, edges.child_quat))
    if len(child):
        q = quat[..., child, :]
        pos[..., child, :] += _rotate(q, edges.child_pos[child])
        quat[..., child, :] = _multiply(q, edges.child_quat[child])
    parent = np.flatnonzero(_not_identity(edges.parent_pos, edges.parent_quat))
    if len(parent):
        conj = edges.parent_quat[parent] * np.array([1.0, -1.0, -1.0, -1.0])
        pos[..., parent, :] = _rotate(conj, pos[..., parent, :] - edges.parent_pos[parent])
        quat[..., parent, :] = _multiply(conj, quat[..., parent, :])
    return pos, quat


def _not_identity(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    return np.any(pos != 0.0, axis=-1) | np.any(quat != _IDENTITY_QUAT, axis=-1)


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products of quaternions w, x, y, z (broadcast over leading axes)."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors v rotated by unit quaternions q: v + 2w (u × v) + 2 u × (u × v)."""
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


class LiveMessages:
    """The reusable live messages of one layout; `messages` refills them sample by sample."""

    def __init__(self, layout: Layout) -> None:
        T = ros.types()
        self.layout = layout
        self._stamp = T["builtin_interfaces/msg/Time"](sec=0, nanosec=0)
        self._clock = T[ros.CLOCK](clock=self._stamp)
        self._clock_cdr = ros.Reencoder(self._clock, ros.CLOCK)
        edges = layout.moving
        transforms = [
            transform_stamped(self._stamp, parent, child, _ORIGIN, _IDENTITY)
            for parent, child in zip(edges.parents, edges.children, strict=True)
        ]
        self._translations = [t.transform.translation for t in transforms]
        self._rotations = [t.transform.rotation for t in transforms]
        self._tf = T[ros.TF](transforms=transforms)
        self._tf_cdr = ros.Reencoder(self._tf, ros.TF)
        entities = layout.entities
        self._joints = [_JointStates(T, layout, e, self._stamp) for e in entities if moves(e)]
        self._odometry = [
            _Odometry(T, layout, e, self._stamp) for e in entities if e.free_qpos >= 0
        ]
        self._drive_tf = [
            _DriveTf(T, e, self._stamp) for e in entities if e.free_qpos >= 0 and e.tf_topic
        ]

    def messages(
        self, samples: Samples, xpos: np.ndarray, xquat: np.ndarray, xmat: np.ndarray
    ) -> Iterator[tuple[Message, ...]]:
        """Each sample's messages in turn, from its body poses (n×nbody×3, ×4, ×9): the same
        objects refilled, so write one sample's messages before taking the next."""
        edges = self.layout.moving
        pos, quat = relative_poses(xpos, xquat, xmat, edges.child_bodies, edges.parent_bodies)
        pos, quat = frame_poses(pos, quat, edges)
        return zip(
            self._clocks(samples),  # first: it sets the stamp that every header shares
            self._transforms(samples, pos, quat),
            *(joints.messages(samples) for joints in self._joints),
            *(odometry.messages(samples, xmat) for odometry in self._odometry),
            *(tf.messages(samples) for tf in self._drive_tf),
            strict=True,
        )

    def _clocks(self, samples: Samples) -> Iterator[Message]:
        stamp = self._stamp
        for t in samples.times.tolist():
            stamp.sec, stamp.nanosec = divmod(ros.nanoseconds(t), 1_000_000_000)
            yield Message(CLOCK.name, ros.CLOCK, t, self._clock, self._clock_cdr)

    def _transforms(self, samples: Samples, pos: np.ndarray, quat: np.ndarray) -> Iterator[Message]:
        translations, rotations = self._translations, self._rotations
        for t, xyzs, wxyzs in zip(samples.times.tolist(), pos.tolist(), quat.tolist(), strict=True):
            for v, (x, y, z) in zip(translations, xyzs, strict=True):
                v.x, v.y, v.z = x, y, z
            for q, (w, x, y, z) in zip(rotations, wxyzs, strict=True):
                q.w, q.x, q.y, q.z = w, x, y, z
            yield Message(TF.name, ros.TF, t, self._tf, self._tf_cdr)


class _JointStates:
    """`/<entity>/joint_states`: position, velocity and actuator effort, as `World.joint_states`
    (a ball joint: its rotation angle and angular speed, no effort)."""

    def __init__(self, T: Any, layout: Layout, e: EntityLayout, stamp: Any) -> None:
        model = layout.model
        self._qpos = model.jnt_qposadr[e.joint_ids]
        self._dofs = model.jnt_dofadr[e.joint_ids]
        self._balls = e.ball_joints
        self._topic = f"{namespace(e.name)}/joint_states"
        self._message = T[ros.JOINT_STATE](
            header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=""),
            name=list(e.joint_names),
            position=np.zeros(len(e.joint_names)),
            velocity=np.zeros(len(e.joint_names)),
            effort=np.zeros(len(e.joint_names)),
        )
        self._cdr = ros.Reencoder(self._message, ros.JOINT_STATE)

    def messages(self, samples: Samples) -> Iterator[Message]:
        qa, da = self._qpos, self._dofs
        # rows must be contiguous for the CDR encoder; indexing column views may give F order
        position, velocity, effort = (
            np.ascontiguousarray(a[:, i])
            for a, i in ((samples.qpos, qa), (samples.qvel, da), (samples.qfrc_actuator, da))
        )
        for k in self._balls:
            position[:, k] = 2.0 * np.arccos(np.minimum(1.0, np.abs(samples.qpos[:, qa[k]])))
            velocity[:, k] = np.linalg.norm(samples.qvel[:, da[k] : da[k] + 3], axis=1)
            effort[:, k] = 0.0
        m = self._message
        rows = zip(samples.times.tolist(), position, velocity, effort, strict=True)
        for t, p, v, e in rows:  # row views: each is encoded before the next is set
            m.position, m.velocity, m.effort = p, v, e
            yield Message(self._topic, ros.JOINT_STATE, t, m, self._cdr)


class _Odometry:
    """`/<entity>/odom` of a floating base: its root's pose in the odometry frame (the world,
    or a diff drive's odometry frame, fixed at the world) and its twist in the root's frame
    (MuJoCo's free-joint linear velocity is global and its angular velocity local)."""

    def __init__(self, T: Any, layout: Layout, e: EntityLayout, stamp: Any) -> None:
        self._qpos, self._dof = e.free_qpos, e.free_dof
        self._root = int(layout.model.dof_bodyid[e.free_dof])  # the free joint's body
        self._topic = e.odom_topic
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
            header=T["std_msgs/msg/Header"](stamp=stamp, frame_id=e.odom_frame),
            child_frame_id=e.root_frame,
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=zeros),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=zeros),
        )
        self._cdr = ros.Reencoder(self._message, ros.ODOMETRY)

    def messages(self, samples: Samples, xmat: np.ndarray) -> Iterator[Message]:
        """From the root body's rotation R (n×9) of each sample: the linear twist is Rᵀ v."""
        poses = samples.qpos[:, self._qpos : self._qpos + 7]
        velocity = samples.qvel[:, self._dof : self._dof + 6]
        rotation = xmat[:, self._root].reshape(-1, 3, 3)
        linear = (velocity[:, None, :3] @ rotation)[:, 0, :]  # row vector · R = (Rᵀ v)ᵀ
        p, o = self._pose.position, self._pose.orientation
        v, w = self._twist.linear, self._twist.angular
        rows = zip(
            samples.times.tolist(), poses.tolist(), linear.tolist(), velocity[:, 3:].tolist(),
            strict=True,
        )  # fmt: skip
        for t, pose, vs, ws in rows:
            p.x, p.y, p.z, o.w, o.x, o.y, o.z = pose
            v.x, v.y, v.z = vs
            w.x, w.y, w.z = ws
            yield Message(self._topic, ros.ODOMETRY, t, self._message, self._cdr)


class _DriveTf:
    """A gz-sim drive system's tf topic (`/model/<entity>/tf`): one transform, odometry frame →
    its child, at the odometry's pose, as ros_gz_bridge hands on the system's Pose_V."""

    def __init__(self, T: Any, e: EntityLayout, stamp: Any) -> None:
        self._qpos, self._topic = e.free_qpos, e.tf_topic
        transform = transform_stamped(stamp, e.odom_frame, e.root_frame, _ORIGIN, _IDENTITY)
        self._translation = transform.transform.translation
        self._rotation = transform.transform.rotation
        self._message = T[ros.TF](transforms=[transform])
        self._cdr = ros.Reencoder(self._message, ros.TF)

    def messages(self, samples: Samples) -> Iterator[Message]:
        """The root's pose in the odometry frame (fixed at the world) of each sample."""
        v, q = self._translation, self._rotation
        poses = samples.qpos[:, self._qpos : self._qpos + 7]
        for t, pose in zip(samples.times.tolist(), poses.tolist(), strict=True):
            v.x, v.y, v.z, q.w, q.x, q.y, q.z = pose
            yield Message(self._topic, ros.TF, t, self._message, self._cdr)
