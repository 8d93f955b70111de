"""One simulated world: its spec, model, data and entities; spawning, deleting and queries.

The in-process engine under the server and `twin validate`. Every public method takes `lock`
(also held by the stepping loop for one batch at a time) and raises TwinError subclasses whose
messages name the entity and the fix. A spawn attaches to the world spec and compiles; on any
failure it removes what it attached (frame, prefixed elements, default classes), so the world is
left exactly as it was. Delete and fixed-base moves work on a copy of the spec. State always
moves between models *by name* (`twin_cli.world.entities`), never by position.

Concepts live in mixins: run control (`world_run`), physics settings (`world_physics`), pushes
and joint commands (`world_control`).
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import mujoco
import numpy as np

from twin_cli.errors import EntityExistsError, EntityNotFoundError, SpawnError
from twin_cli.world import actuation as control
from twin_cli.world import placement, posture, queries, shared_meshes, spawn
from twin_cli.world.batch import BatchSpawning
from twin_cli.world.contacts import cap_contact_stiffness
from twin_cli.world.divergence import Divergence
from twin_cli.world.driving import EntityControl
from twin_cli.world.engine_threads import EngineThreads
from twin_cli.world.entities import (
    Entity,
    EntityIndex,
    EntityState,
    element_names,
    index_entities,
    move_states,
    rest_state,
    write_state,
)
from twin_cli.world.loop import SteppingLoop, WorldLock
from twin_cli.world.observers import Observers
from twin_cli.world.physics import PhysicsSettings
from twin_cli.world.pose import Pose, quat_multiply, rotate
from twin_cli.world.queries import JointState
from twin_cli.world.respec import SpecRenewal
from twin_cli.world.running import STATE, RunControl
from twin_cli.world.scene import build_world_spec, replace_lights
from twin_cli.world.sensor_rings import align_sensor_ticks
from twin_cli.world.values import (
    EntityInfo,
    SpawnResult,
    WorldSettings,
    check_settings,
    scene_settings,
)

__all__ = ["World"]

WARNINGS_KEPT = 100  # MuJoCo warning texts kept in World.mujoco_warnings
_Built = tuple[mujoco.MjModel, mujoco.MjData, dict[str, EntityIndex]]


class World(RunControl, PhysicsSettings, EntityControl, BatchSpawning, EngineThreads, SpecRenewal):
    """A MuJoCo world with Gazebo's defaults, entities spawned by name, and a real-time loop."""

    file_notes: tuple[str, ...] = ()  # what a world file held that twin does not simulate

    def __init__(self, settings: WorldSettings | None = None, *, name: str = "default") -> None:
        self.settings = settings or WorldSettings()
        check_settings(self.settings)
        self.name = name
        self.lock = WorldLock()
        self._spec = build_world_spec(scene_settings(self.settings))
        self.model = self._spec.compile()
        self.data = mujoco.MjData(self.model)
        self._entities: dict[str, Entity] = {}
        self._index: dict[str, EntityIndex] = {}
        self._commands: dict[str, control.JointCommand] = {}
        self._pushes: list[control.Push] = []
        self._perturbation: dict[str, tuple[float, ...]] = {}  # a viewer's drag, by body
        self._damping: control.Damping | None = None
        self._iterations = 0
        self._stepping_time = 0.0  # [s] inside mj_step (RunControl.stepping_time)
        self._paused = False
        self.divergences = 0
        self.divergence_log: list[Divergence] = []
        self.mujoco_warnings: deque[str] = deque(maxlen=WARNINGS_KEPT)
        self._snapshot = np.empty(mujoco.mj_stateSize(self.model, STATE))
        self._observers = Observers()  # recorder, live stream: called between batches
        self._loop = SteppingLoop(self)

    # ----------------------------------------------------------------- spawning and deleting
    def spawn(
        self,
        source: str | os.PathLike | mujoco.MjSpec,
        *,
        name: str | None = None,
        pose: Pose = Pose(),
        args: dict[str, str] | None = None,
        package_paths: dict[str, str] | None = None,
        on_ground: bool = False,
        joints: dict[str, float] | None = None,
        env: dict[str, str] | None = None,
        repair_inertia: bool = False,
    ) -> SpawnResult:
        """Adds an entity at `pose`; existing entities keep their exact state.

        The source is read (and converted) before the lock is taken, so a slow conversion does
        not stall the loop. The new entity starts at rest in its own initial configuration
        (its `home` key if it has one) with `joints` (Gazebo's `spawn_model -J`: joint name
        without prefix → position [rad] or [m]) written over it; mimic followers follow their
        leaders. That start is its spawn state (what `reset` returns to). Returns once the
        entity is in the world.

        Raises:
            EntityExistsError: `name` is taken. SpawnError: unreadable source or compile error.
            PartNotFoundError: a `joints` name is not a hinge/slide joint of the entity.
            InvalidRequestError: a `joints` value is outside its joint's range (or sets a mimic
                follower). On any error the world is unchanged.
            converters.ConversionError: the converter refused the file.
        """
        if name is not None:
            spawn.check_entity_name(name)
        loaded = spawn.load_source(source, args, package_paths, env, repair_inertia)
        with self.lock:
            name = self._free_name(name, loaded.default_name)
            try:
                home = self._attach(loaded, name, pose)
                pose, state, (model, data, index) = self._seed(
                    loaded, name, pose, home, on_ground, joints or {}
                )
                warnings = [
                    *loaded.notes,
                    *placement.start_warnings(model, data, index, name, pose.z),
                ]
            except BaseException:
                spawn.remove_entity(self._spec, name)  # the world spec as it was before
                raise
            self._entities[name] = Entity(
                name,
                loaded.source,
                dict(args or {}),
                dict(package_paths or {}),
                pose,
                on_ground,
                state,
                loaded.report,
                loaded.xml,
                dict(joints or {}),
                loaded.description,
                sensors=loaded.sensors,
                plugins=loaded.plugins,
                env=env,
                repair_inertia=repair_inertia,
            )
            self._commit(self._spec, model, data, index)
            return SpawnResult(name, loaded.source, warnings, loaded.report, loaded.cached)

    def _attach(self, loaded: spawn.LoadedSource, name: str, pose: Pose) -> np.ndarray | None:
        """Attaches the loaded spec to the world spec as `name`; returns its home qpos or None."""
        try:
            home = spawn.prepare_child(loaded.spec, self._spec)
            self._keep_spec(name, loaded.spec, loaded.mesh_keys)  # for renew_spec
            shared_meshes.prepare(loaded.spec, self._spec, loaded.mesh_keys)
            spawn.attach(self._spec, loaded.spec, name, pose)
        except ValueError as exc:
            raise SpawnError(
                name, loaded.source, f"cannot be attached ({exc})", "fix the model"
            ) from exc
        return home

    def _seed(
        self,
        loaded: spawn.LoadedSource,
        name: str,
        pose: Pose,
        home: np.ndarray | None,
        on_ground: bool,
        joints: dict[str, float],
    ) -> tuple[Pose, EntityState, _Built]:
        """Compiles the world with the attached entity and writes its initial state at rest."""
        model, data, index = self._rebuild(self._spec, name, loaded.source)
        ix = index[name]
        targets = posture.joint_targets(model, ix.joints, f"{name}/", joints, name)
        q = posture.apply_targets(spawn.initial_qpos(model, ix, home, pose), ix.qpos, targets)
        if on_ground:
            pose, q, (model, data, index) = self._ground(model, data, index, name, pose, q)
        state = rest_state(model, index[name], q)
        write_state(data, index[name], state)
        return pose, state, (model, data, index)

    def delete(self, name: str) -> None:
        """Removes entity `name`; the others keep their exact state."""
        with self.lock:
            self._require(name)
            trial = self._spec.copy()
            spawn.remove_entity(trial, name)
            entity = self._entities.pop(name)
            try:
                model, data, index = self._rebuild(trial, None, entity.source)
            except SpawnError:
                self._entities[name] = entity
                raise
            self._commands = {
                k: c for k, c in self._commands.items() if not k.startswith(f"{name}/")
            }
            self._pushes = [p for p in self._pushes if not p.body.startswith(f"{name}/")]
            self._perturbation = {
                b: w for b, w in self._perturbation.items() if not b.startswith(f"{name}/")
            }
            self._commit(trial, model, data, index)
            self._count_delete()  # every RENEW_EVERY deletes: a fresh spec (bounded memory)

    def _free_name(self, name: str | None, default: str) -> str:
        if name is not None:
            if name in self._entities:
                raise EntityExistsError(name)
            return name
        base = "".join(c if c.isalnum() or c in "-_." else "_" for c in default) or "model"
        candidate, k = base, 0
        while candidate in self._entities:
            k += 1
            candidate = f"{base}_{k}"
        return candidate

    def set_lights(self, lights: Sequence[Any]) -> None:
        """Replace the world's lights (an SDF world's `<light>`s, its included `sun` among them)."""
        with self.lock:
            trial = self._spec.copy()
            replace_lights(trial, lights)
            self._commit(trial, *self._rebuild(trial, None, "<lights>"))
            self._lights = list(lights)  # replayed by renew_spec

    def _rebuild(self, trial: mujoco.MjSpec, new: str | None, source: str) -> _Built:
        """Compiles `trial` into a new model and data carrying every existing entity's state."""
        try:
            model, data = trial.recompile(self.model, self.data)
        except (ValueError, RuntimeError) as exc:
            raise SpawnError(
                new or "world",
                source,
                f"the world does not compile with it ({exc})",
                "fix the model; the world is unchanged",
            ) from exc
        kept = [n for n in self._entities if n in self._index]
        index = index_entities(model, kept + ([new] if new else []))
        move_states(self.data, self._index, data, index, [n for n in kept if n in index])
        data.time = self.data.time
        self._reapply_commands(model, data)
        return model, data, index

    def _ground(self, model, data, index, name, pose, q):  # noqa: ANN001, ANN202
        """Shifts the new entity so its lowest collision point rests on z = 0."""
        ix = index[name]
        full = data.qpos.copy()
        full[ix.qpos] = q
        scratch = placement.positioned(model, full)
        low = placement.lowest_point(model, scratch, placement.collision_geoms(model, ix.geoms))
        if low is None:
            return pose, q, (model, data, index)
        pose = replace(pose, z=pose.z - low)
        if ix.free_qpos >= 0:
            q = q.copy()
            for at in spawn.free_offsets(model, ix):  # every free link, not only the root
                q[at + 2] -= low
            return pose, q, (model, data, index)
        spawn.move_frame(self._spec, name, pose)
        model, data, index = self._rebuild(self._spec, name, "on-ground placement")
        return pose, q, (model, data, index)  # joint values keep their layout; only the frame moved

    def _commit(
        self,
        spec: mujoco.MjSpec,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        index: dict[str, EntityIndex],
    ) -> None:
        self._spec, self.model, self.data, self._index = spec, model, data, index
        align_sensor_ticks(model, data)
        self._install_pool(model, data)
        cap_contact_stiffness(model)
        self._snapshot = np.empty(mujoco.mj_stateSize(model, STATE))
        self._damping = control.damping_of(model, element_names(model, model.name_numericadr))
        control.apply_pushes(
            model,
            data,
            self._pushes,
            {p.body for p in self._pushes} | set(self._perturbation),
            self._perturbation,
        )

    # ----------------------------------------------------------------- entities
    def _require(self, name: str) -> EntityIndex:
        if name not in self._entities:
            raise EntityNotFoundError(name, list(self._entities))
        return self._index[name]

    def entities(self) -> list[EntityInfo]:
        """Every entity: name, source, root position [m], number of joints (free excluded)."""
        with self.lock:
            return [
                EntityInfo(
                    n,
                    e.source,
                    self.get_pose(n).position(),
                    len(queries.joint_names(self.model, self._index[n], f"{n}/")),
                )
                for n, e in self._entities.items()
            ]

    def get_pose(self, name: str) -> Pose:
        """The entity's root pose now."""
        with self.lock:
            ix = self._require(name)
            return queries.root_pose(self.model, self.data, ix, self._entities[name].pose)

    def set_pose(self, name: str, pose: Pose) -> None:
        """Teleports the entity's root to `pose`, at rest (its velocities are zeroed).

        A fixed-base entity is moved by moving its attach frame (a recompile); that also becomes
        its spawn pose.
        """
        with self.lock:
            ix = self._require(name)
            if ix.free_qpos < 0:
                trial = self._spec.copy()
                spawn.move_frame(trial, name, pose)
                self._entities[name] = replace(self._entities[name], pose=pose)
                self._commit(trial, *self._rebuild(trial, None, self._entities[name].source))
                return
            if ix.model_site >= 0 and self.model.site_bodyid[ix.model_site] == 0:
                self._move_free_links(name, ix, pose)  # unjoined links: all move with the frame
                return
            if ix.model_site >= 0:
                pose = queries.root_from_model(self.model, ix, pose)
            self.data.qpos[ix.free_qpos : ix.free_qpos + 3] = pose.position()
            self.data.qpos[ix.free_qpos + 3 : ix.free_qpos + 7] = pose.quat()
            self.data.qvel[ix.dofs] = 0.0
            self.data.qacc_warmstart[ix.dofs] = 0.0

    def _move_free_links(self, name: str, ix: EntityIndex, pose: Pose) -> None:
        """Moves every free link of a model of unjoined links rigidly, so that its model frame
        goes from where it is (its spawn or last set pose) to `pose`; at rest."""
        old = self._entities[name].pose
        w, x, y, z = old.quat()
        turn = quat_multiply(pose.quat(), (w, -x, -y, -z))
        for at in spawn.free_offsets(self.model, ix):
            a = int(ix.qpos[at])
            offset = tuple(float(v) for v in self.data.qpos[a : a + 3] - old.position())
            self.data.qpos[a : a + 3] = np.add(pose.position(), rotate(turn, offset))  # type: ignore[arg-type]
            link_quat = tuple(float(v) for v in self.data.qpos[a + 3 : a + 7])
            self.data.qpos[a + 3 : a + 7] = quat_multiply(turn, link_quat)  # type: ignore[arg-type]
        self.data.qvel[ix.dofs] = 0.0
        self.data.qacc_warmstart[ix.dofs] = 0.0
        self._entities[name] = replace(self._entities[name], pose=pose)

    def joint_states(self, name: str) -> list[JointState]:
        """Position, velocity and actuator effort of each joint (free joint excluded)."""
        with self.lock:
            return queries.joint_states(self.model, self.data, self._require(name), f"{name}/")

    def link_poses(self, name: str) -> dict[str, Pose]:
        """World pose of each of the entity's bodies (links), by name without prefix."""
        with self.lock:
            return queries.link_poses(self.model, self.data, self._require(name), f"{name}/")

    # ----------------------------------------------------------------- files
    def save(self, path: str | os.PathLike) -> None:
        """Writes entities, sources, settings and the full state to `path` (atomically)."""
        from twin_cli.world import savefile as worldfile

        with self.lock:
            worldfile.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> World:
        """A new, stopped world rebuilt from a file written by `save`."""
        from twin_cli.world import savefile as worldfile

        return worldfile.load(cls, path)
