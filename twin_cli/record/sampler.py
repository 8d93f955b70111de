"""One copy of the world's state under its lock; the kinematics of that copy outside it.

`Sampler.capture` runs in the stepping thread between batches (the loop waits): it copies time,
qpos, qvel, actuator forces and mocap poses (about 5 µs for a humanoid) and nothing else. Link
poses are recomputed from the copied qpos with `mj_kinematics` on the consumer's own scratch
data, exactly as `World.link_poses` does (after `mj_step` the live `xpos` is one step old).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from twin_cli.errors import EntityNotFoundError
from twin_cli.record.frames import Sources, prefix_template, sources_of
from twin_cli.record.layout import Layout, make_layout
from twin_cli.world.observers import WorldView, world_view
from twin_cli.world.velocity_motors import joint_efforts

if TYPE_CHECKING:
    from twin_cli.world.engine import World


@dataclass(frozen=True)
class Sample:
    """The observed state at one sim time (copies; safe to use outside the lock).

    Attributes:
        time: sim time [s]; layout: the frames and joints of `layout.model`.
        qpos, qvel, qfrc_actuator: the whole model's vectors; mocap_pos, mocap_quat likewise.
    """

    time: float
    layout: Layout
    qpos: np.ndarray
    qvel: np.ndarray
    qfrc_actuator: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray


class Sampler:
    """Copies the state of some (or all) entities of a world, re-reading its layout on change."""

    def __init__(
        self,
        world: World,
        entities: Sequence[str] = (),
        descriptions: dict[str, str] | None = None,
        frame_prefix: str | None = None,
    ) -> None:
        """Args:
        world: a `twin_cli.world.World`.
        entities: entity names to observe; empty: all, including ones spawned later.
        descriptions: URDF text by entity name, overriding what the world kept (validation
            spawns an MjSpec and knows the URDF).
        frame_prefix: the tf frame prefix template (`frames.prefix_template`).

        Raises:
            EntityNotFoundError: a name the world does not have.
        """
        self._world = world
        self._names = tuple(entities)
        self._descriptions = dict(descriptions or {})
        self.frame_prefix = prefix_template(frame_prefix)
        self._model: mujoco.MjModel | None = None
        self._layout: Layout | None = None
        with world.lock:
            known = list(world_view(world).index)
        for name in self._names:
            if name not in known:
                raise EntityNotFoundError(name, known)

    def capture(self) -> Sample:
        """The state now; call with `world.lock` held (the stepping thread holds it)."""
        world = self._world
        if world.model is not self._model:
            self._relayout()
        d = world.data
        assert self._layout is not None
        return Sample(
            float(d.time),
            self._layout,
            d.qpos.copy(),
            d.qvel.copy(),
            joint_efforts(world.model, d),  # a velocity motor's joint: its tendon's force
            d.mocap_pos.copy(),
            d.mocap_quat.copy(),
        )

    def selection(self, view: WorldView) -> tuple[dict, dict[str, Sources]]:
        """The observed entities' index (name → EntityIndex) and what their frames are named
        from (name → `frames.Sources`) in `view`; call with the world's lock held."""
        names = self._names or tuple(view.index)
        index = {n: view.index[n] for n in names if n in view.index}
        sources = {
            n: sources_of(self._world, n, self.frame_prefix, self._descriptions.get(n))
            for n in index
        }
        return index, sources

    def _relayout(self) -> None:
        view = world_view(self._world)
        self._layout = make_layout(view.model, *self.selection(view))
        self._model = view.model


@dataclass(frozen=True)
class Samples:
    """Consecutive samples of one layout as rows: what a consumer turns into messages at once.

    The encoder's rows are views into the records it read from its ring (no copies); a single
    `Sample` is a batch of one (`of`).

    Attributes:
        layout: the frames and joints of `layout.model`; times: sim times [s] (n).
        qpos (n×nq), qvel, qfrc_actuator (n×nv), mocap_pos (n×nmocap×3), mocap_quat (n×nmocap×4).
    """

    layout: Layout
    times: np.ndarray
    qpos: np.ndarray
    qvel: np.ndarray
    qfrc_actuator: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray

    @classmethod
    def of(cls, sample: Sample) -> Samples:
        """One sample as a batch of one (views)."""
        rows = (sample.qpos, sample.qvel, sample.qfrc_actuator, sample.mocap_pos, sample.mocap_quat)
        return cls(sample.layout, np.array([sample.time]), *(a[None] for a in rows))

    def __len__(self) -> int:
        return len(self.times)

    def with_exact_mimics(self) -> Samples:
        """The samples with each mimic follower's position and speed set from its leader's
        (copies; the samples themselves may be views into the encoder's ring)."""
        m = self.layout.mimics
        if not len(m.offset):
            return self
        qpos, qvel = self.qpos.copy(), self.qvel.copy()
        for _ in range(len(m.offset)):  # a leader that follows another is set first
            qpos[:, m.follower_qpos] = (
                m.follower_ref + m.offset + m.multiplier * (qpos[:, m.leader_qpos] - m.leader_ref)
            )
            qvel[:, m.follower_dof] = m.multiplier * qvel[:, m.leader_dof]
            if not np.isin(m.leader_qpos, m.follower_qpos).any():
                break
        return Samples(
            self.layout, self.times, qpos, qvel, self.qfrc_actuator, self.mocap_pos,
            self.mocap_quat,
        )  # fmt: skip

    def finite(self) -> Samples:
        """The samples without the diverged ones (an entity being reset by the world)."""
        keep = np.isfinite(self.qpos).all(axis=1) & np.isfinite(self.qvel).all(axis=1)
        if keep.all():
            return self
        return Samples(
            self.layout, self.times[keep], self.qpos[keep], self.qvel[keep],
            self.qfrc_actuator[keep], self.mocap_pos[keep], self.mocap_quat[keep],
        )  # fmt: skip


class Kinematics:
    """Body poses of samples, on scratch data of the samples' model (consumer side)."""

    def __init__(self) -> None:
        self._model: mujoco.MjModel | None = None
        self._data: mujoco.MjData | None = None

    def poses(self, samples: Samples) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World positions [m] (n×nbody×3), quaternions w,x,y,z (n×nbody×4) and rotation
        matrices (n×nbody×9) of every body in each sample."""
        model = samples.layout.model
        if model is not self._model:
            self._model, self._data = model, mujoco.MjData(model)
        d, n = self._data, len(samples)
        xpos, xquat = np.empty((n, model.nbody, 3)), np.empty((n, model.nbody, 4))
        xmat = np.empty((n, model.nbody, 9))
        qpos, mocap_pos, mocap_quat = d.qpos, d.mocap_pos, d.mocap_quat  # views, looked up once
        for i in range(n):
            qpos[:] = samples.qpos[i]
            if model.nmocap:
                mocap_pos[:], mocap_quat[:] = samples.mocap_pos[i], samples.mocap_quat[i]
            mujoco.mj_kinematics(model, d)
            xpos[i], xquat[i], xmat[i] = d.xpos, d.xquat, d.xmat
        return xpos, xquat, xmat
