"""One simulated world: the engine's public face, composed of its state and the modules that act.

The in-process engine under the server and `twin validate`. `World` owns one `WorldState`
(`state`) and one stepping thread (`loop`); every method hands the state to the function that
does the job (`spawning`, `changes`, `running`, `physics`, `driving`, `engine_threads`,
`respec`, `snapshot`) and each of those takes the lock. Errors are TwinError subclasses whose
messages name the entity and the fix; a failed change leaves the world exactly as it was. State
always moves between models by name (`twin_cli.world.entities`), never by position.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import mujoco

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import (
    changes,
    decomposing,
    driving,
    engine_threads,
    physics,
    queries,
    respec,
    running,
    spawning,
)
from twin_cli.world import snapshot as snapshots
from twin_cli.world.actuation import JointCommand
from twin_cli.world.divergence import Divergence
from twin_cli.world.entities import Entity, EntityIndex
from twin_cli.world.loop import LoopFigures, SteppingLoop, WorldLock
from twin_cli.world.page_model import plugin_free
from twin_cli.world.pose import Pose
from twin_cli.world.queries import JointState
from twin_cli.world.scene import build_world_spec
from twin_cli.world.snapshot import WorldSnapshot
from twin_cli.world.spawn import LoadedSource
from twin_cli.world.state import WorldState
from twin_cli.world.values import (
    EntityInfo,
    SpawnResult,
    Stats,
    WorldSettings,
    check_settings,
    hull_stand_ins,
    scene_settings,
)

if TYPE_CHECKING:
    from converters.description import Light

__all__ = ["World"]


class World:
    """A MuJoCo world with Gazebo's defaults, entities spawned by name, and a real-time loop."""

    def __init__(self, settings: WorldSettings | None = None, *, name: str = "default") -> None:
        settings = settings or WorldSettings()
        check_settings(settings)
        spec = build_world_spec(scene_settings(settings))
        model = spec.compile()
        self._state = WorldState(name, settings, WorldLock(), spec, model, mujoco.MjData(model))
        self._loop = SteppingLoop(self._state)

    # ----------------------------------------------------------------- what it is
    @property
    def name(self) -> str:
        return self._state.name

    @property
    def settings(self) -> WorldSettings:
        """The physics settings (changed through `set_physics` and `set_gravity`)."""
        return self._state.settings

    @property
    def lock(self) -> WorldLock:
        """Held by the stepping loop for one batch at a time; hold it to read model and data."""
        return self._state.lock

    @property
    def model(self) -> mujoco.MjModel:
        """The compiled model (a new one after every spawn, delete or fixed-base move)."""
        return self._state.model

    @property
    def data(self) -> mujoco.MjData:
        return self._state.data

    def page_model(self) -> mujoco.MjModel:
        """The model a browser's MuJoCo can load (`twin_cli.world.page_model`): the world's
        own when it uses no plugin, else a copy without them, made once per model (compiled
        outside the lock when the caller does not hold it) and given the world's options."""
        state = self._state
        with state.lock:
            model, shown = state.model, state.page_model
            if model.nplugin == 0:
                return model
            if shown is not None and shown[0] is model:
                shown[1].opt = model.opt  # the options the world changes in place
                return shown[1]
            spec = state.spec.copy()
        page = plugin_free(spec)
        with state.lock:
            page.opt = state.model.opt
            if state.model is model:
                state.page_model = (model, page)
        return page

    @property
    def divergences(self) -> int:
        """Entities reset to their spawn state after their state went bad."""
        return self._state.divergences

    @property
    def divergence_log(self) -> list[Divergence]:
        return list(self._state.divergence_log)

    @property
    def mujoco_warnings(self) -> list[str]:
        """MuJoCo's warning texts, the last hundred."""
        return list(self._state.mujoco_warnings)

    @property
    def file_notes(self) -> tuple[str, ...]:
        """What a world file held that twin does not simulate."""
        return self._state.file_notes

    @file_notes.setter
    def file_notes(self, notes: Sequence[str]) -> None:
        self._state.file_notes = tuple(notes)

    # ----------------------------------------------------------------- spawning, changing
    def spawn(
        self, request: SpawnRequest | Any, *, name: str | None = None, pose: Pose = Pose()
    ) -> SpawnResult:
        """Adds one entity (`spawning.spawn_one`): a request, or a bare path or MjSpec."""
        return spawning.spawn_one(self._state, request, name=name, pose=pose)

    def spawn_batch(
        self,
        request: SpawnRequest | Any,
        *,
        poses: Sequence[Pose],
        names: Sequence[str] | None = None,
        base: str | None = None,
    ) -> list[SpawnResult]:
        """Adds one entity per pose, one conversion and one compile (`spawning.spawn_batch`)."""
        return spawning.spawn_batch(self._state, request, poses=poses, names=names, base=base)

    def spawn_specs(
        self,
        items: Sequence[tuple[mujoco.MjSpec | LoadedSource, str, Pose]],
        redo: Mapping[str, Any] | None = None,
    ) -> list[SpawnResult]:
        """Adds a world file's models in one compile, their decompositions left for the
        background where `redo` gives a model's full conversion (`spawning.spawn_specs`)."""
        return spawning.spawn_specs(self._state, items, redo)

    def delete(self, name: str) -> None:
        """Removes entity `name`; the others keep their exact state."""
        changes.delete(self._state, name)

    def set_lights(self, lights: Sequence[Light]) -> None:
        """Replace the world's lights (an SDF world's `<light>`s)."""
        changes.set_lights(self._state, lights)

    def set_pose(self, name: str, pose: Pose) -> None:
        """Teleports the entity's root to `pose`, at rest (`changes.set_pose`)."""
        changes.set_pose(self._state, name, pose)

    def set_twist(
        self,
        name: str,
        linear: tuple[float, float, float],
        angular: tuple[float, float, float],
    ) -> None:
        """Sets a free-floating entity's root velocity, world frame (`changes.set_twist`)."""
        changes.set_twist(self._state, name, linear, angular)

    def get_twist(self, name: str) -> queries.Twist:
        """(linear [m/s], angular [rad/s]) of the entity's root origin, world frame."""
        state = self._state
        with self.lock:
            return queries.root_twist(state.model, state.data, state.require(name))

    # ----------------------------------------------------------------- entities
    def entity(self, name: str) -> Entity:
        """The record of entity `name`: its request, spawn pose and state, sensors, plugins.

        Raises:
            EntityNotFoundError: no such entity (the message lists the entities).
        """
        with self.lock:
            self._state.require(name)
            return self._state.entities[name]

    def entity_names(self) -> list[str]:
        """The entities' names, in spawn order."""
        with self.lock:
            return list(self._state.entities)

    def index_of(self, name: str) -> EntityIndex:
        """Where entity `name` lives in the current model (ids and addresses; they change at
        every compile, so read them again after a spawn or delete).

        Raises:
            EntityNotFoundError: no such entity.
        """
        with self.lock:
            return self._state.require(name)

    def entities(self) -> list[EntityInfo]:
        """Every entity: name, source, root position [m], number of joints (free excluded),
        hull stand-ins and its background decomposition's status (`EntityInfo`)."""
        state = self._state
        with self.lock:
            return [
                EntityInfo(
                    n,
                    e.source,
                    self.get_pose(n).position(),
                    len(queries.joint_names(state.model, state.index[n], f"{n}/")),
                    hull_stand_ins(e.report),
                    decomposing.status(state, n),
                )
                for n, e in state.entities.items()
            ]

    def get_pose(self, name: str) -> Pose:
        """The entity's root pose now."""
        state = self._state
        with self.lock:
            ix = state.require(name)
            return queries.root_pose(state.model, state.data, ix, state.entities[name].pose)

    def joint_states(self, name: str) -> list[JointState]:
        """Position, velocity and actuator effort of each joint (free joint excluded)."""
        state = self._state
        with self.lock:
            return queries.joint_states(state.model, state.data, state.require(name), f"{name}/")

    def link_poses(self, name: str) -> dict[str, Pose]:
        """World pose of each of the entity's bodies (links), by name without prefix."""
        state = self._state
        with self.lock:
            return queries.link_poses(state.model, state.data, state.require(name), f"{name}/")

    # ----------------------------------------------------------------- driving
    def push(
        self,
        name: str,
        force: tuple[float, float, float] = (0.0, 0.0, 0.0),
        torque: tuple[float, float, float] = (0.0, 0.0, 0.0),
        *,
        link: str | None = None,
        duration: float = 0.1,
    ) -> None:
        """A world-frame force [N] and torque [N m] on a link for `duration` [s] of sim time."""
        driving.push(self._state, name, force, torque, link=link, duration=duration)

    def set_controls(self, actuators: Sequence[int], values: Sequence[float]) -> None:
        """Writes actuators' ctrl, waking what they move (`driving.set_controls`)."""
        driving.set_controls(self._state, actuators, values)

    def set_joint_forces(self, dofs: Sequence[int], forces: Sequence[float]) -> None:
        """Generalised forces on dofs until changed (`driving.set_joint_forces`)."""
        driving.set_joint_forces(self._state, dofs, forces)

    def follow_references(
        self, actuators: Sequence[int], references: tuple, bias: Sequence[float]
    ) -> None:
        """One trajectory update of position servos (`driving.follow_references`)."""
        driving.follow_references(self._state, actuators, references, bias)

    def hold_servo(self, actuator: int, ctrl: float) -> None:
        """Stops a position servo at `ctrl` without feed-forward (`driving.hold_servo`)."""
        driving.hold_servo(self._state, actuator, ctrl)

    def energy(self) -> float:
        """Total mechanical energy now [J], MuJoCo's energy computation switched on for it."""
        state = self._state
        with self.lock:
            state.model.opt.enableflags |= int(mujoco.mjtEnableBit.mjENBL_ENERGY)
            mujoco.mj_forward(state.model, state.data)
            return float(state.data.energy[0] + state.data.energy[1])

    def perturb(self, wrenches: dict[str, Sequence[float]]) -> None:
        """Sets a viewer's mouse drag: world-frame wrench [N, N m] per full body name."""
        driving.perturb(self._state, wrenches)

    def command(self, name: str, joint: str, *, mode: str, value: float) -> None:
        """Sets one joint's target, clipped to what the joint allows (`driving.command`)."""
        driving.command(self._state, name, joint, mode=mode, value=value)

    def command_joints(
        self, name: str, targets: dict[str, float], *, mode: str, clip: bool = False
    ) -> list[JointCommand]:
        """Sets several joints' targets at once, all or none (`driving.command_joints`)."""
        return driving.command_joints(self._state, name, targets, mode=mode, clip=clip)

    def commands(self) -> Mapping[str, JointCommand]:
        """The joint commands held, by actuator name: a read-only live view (hold the lock
        while reading it from another thread)."""
        return MappingProxyType(self._state.commands)

    def joint_commands(self, name: str) -> dict[str, dict]:
        """Each actuated joint's mode, target, gains and limits (`twin joints`)."""
        with self.lock:
            return driving.joint_commands(self._state, name)

    def record_targets(
        self,
        targets: Mapping[str, tuple[float, float]],
        held: Mapping[str, JointCommand] | None = None,
    ) -> None:
        """Records where a controller left position servos: actuator name → (target [rad or
        m], feedforward velocity); commands that no longer exist, or that replaced the ones
        the controller `held`, are skipped."""
        driving.record_targets(self._state, targets, held)

    # ----------------------------------------------------------------- running
    @property
    def paused(self) -> bool:
        """Whether the real-time loop is paused (`step` still works)."""
        return self._state.paused

    def pause(self) -> None:
        with self.lock:
            self._state.paused = True

    def resume(self) -> None:
        """Resumes the real-time loop (the pacer re-anchors: no catch-up burst)."""
        with self.lock:
            self._state.paused = False
            self._loop.reanchor()

    def step(self, n: int = 1) -> None:
        """Steps `n` times now (paused or not)."""
        running.step(self._state, n)

    def reset(self, *, time_only: bool = False) -> None:
        """Every entity back to its spawn state and time to 0 (or only time and iterations)."""
        running.reset(self._state, self._loop, time_only=time_only)

    def stats(self) -> Stats:
        """`gz stats` figures (factor averaged over the last 20 samples of 0.2 s)."""
        return running.stats(self._state, self._loop)

    @property
    def stepping_time(self) -> float:
        """Wall time [s] spent inside mj_step since the world was made.

        Over a window of the unthrottled loop, its share of the window's wall time is the loop's
        throughput against raw mj_step on the very same steps at the very same moment.
        """
        return self._state.stepping_time

    def loop_figures(self) -> LoopFigures:
        """The loop's own measurements (factor, real time, lateness, dropped steps)."""
        return self._loop.figures()

    def start(self) -> None:
        """Starts the real-time stepping thread."""
        self._loop.start()

    def stop(self) -> None:
        """Stops and joins the stepping thread, and cancels the background decompositions
        (`decomposing.cancel_all`): a server stops a world it drops (exit, `twin load`)."""
        self._loop.stop()
        with self.lock:
            decomposing.cancel_all(self._state, "the world stopped before it was ready")

    @property
    def running(self) -> bool:
        return self._loop.running

    def add_observer(
        self, callback: Callable[[], None], rate: float, *, aligned: bool = False
    ) -> int:
        """Calls `callback()` every 1/`rate` [Hz] of sim time, between steps, lock held.

        For consumers of the world (recorder, live stream, sensors): the stepping splits its
        `mj_step(nstep)` calls where an observer is due, so there is no Python per physics step.
        The callback must only copy what it needs. `aligned`: at sim times k/`rate` rather than
        from now (`Observers.add`). Returns a handle for `remove_observer`.
        """
        state = self._state
        with self.lock:
            return state.observers.add(
                callback,
                rate,
                float(state.data.time),
                state.model.opt.timestep,
                aligned=aligned,
            )

    def remove_observer(self, handle: int) -> None:
        """Stops calling an observer (may be called from within its callback)."""
        with self.lock:
            self._state.observers.remove(handle)

    # ----------------------------------------------------------------- physics and engine
    def gravity(self) -> tuple[float, float, float]:
        """The gravity vector [m/s²]."""
        return physics.gravity(self._state)

    def set_gravity(self, vector: tuple[float, float, float]) -> None:
        """Sets gravity [m/s²]; takes effect on the next step."""
        physics.set_gravity(self._state, vector)

    def physics(self) -> dict:
        """Timestep, rate, iterations, solver, integrator, gravity, threads, sleeping."""
        return physics.physics(self._state)

    def set_physics(self, **changes: Any) -> dict:
        """Changes any of the physics settings (`physics.set_physics`); returns `physics()`."""
        return physics.set_physics(self._state, self._loop, **changes)

    def set_engine(
        self,
        *,
        threads: int | None = None,
        sleep: bool | None = None,
        sleep_tolerance: float | None = None,
    ) -> None:
        """Sets the engine threads, sleeping and its tolerance [m/s] (None keeps a value)."""
        engine_threads.set_engine(
            self._state, threads=threads, sleep=sleep, sleep_tolerance=sleep_tolerance
        )

    @property
    def threads(self) -> int:
        """Engine threads asked for (the pool is installed when `pool_threads` > 0)."""
        return engine_threads.threads_of(self._state)

    @property
    def pool_threads(self) -> int:
        """Worker threads of the pool on the current data (0: no pool, single-threaded)."""
        return self._state.pool_threads

    @property
    def sleeping(self) -> bool:
        """Whether island sleeping is enabled."""
        return engine_threads.sleeping(self._state.model)

    def renew_spec(self) -> bool:
        """Rebuilds the world spec from scratch if it compiles to exactly the running model."""
        with self.lock:
            return respec.renew_spec(self._state)

    @property
    def spec_renewals(self) -> int:
        return self._state.spec_renewals

    @property
    def spec_renewals_refused(self) -> int:
        return self._state.spec_renewals_refused

    # ----------------------------------------------------------------- snapshots
    def snapshot(self) -> WorldSnapshot:
        """Settings, entities, commands and full state, copied under the lock."""
        return snapshots.take(self._state)

    def restore(self, snapshot: WorldSnapshot) -> None:
        """Writes a snapshot into this world, which holds the same entities (`snapshot.restore`).

        Raises:
            InvalidRequestError: other entities, or another layout; the world is unchanged.
        """
        snapshots.restore(self._state, snapshot)
