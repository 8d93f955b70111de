"""One simulated world: its spec, model, data and entities, physics settings and run control.

The in-process engine under the server and `twin validate`. Every public method takes `lock`
(also held by the stepping loop for one batch at a time) and raises TwinError subclasses whose
messages name the entity and the fix. Model-changing requests (spawn, delete) work on a copy
of the spec and commit only after it compiled, so a failure leaves the world exactly as it was.
State always moves between models *by name* (`twin_cli.entities`), never by position.
"""

from __future__ import annotations

import math
import os
from collections import deque
from dataclasses import replace

import mujoco
import numpy as np

from twin_cli import control, placement, queries, spawn
from twin_cli.divergence import Divergence, find_divergent, warning_counts
from twin_cli.entities import (
    Entity,
    EntityIndex,
    capture_state,
    element_names,
    index_entities,
    rest_state,
    write_state,
)
from twin_cli.errors import (
    EntityExistsError,
    EntityNotFoundError,
    InvalidRequestError,
    PartNotFoundError,
    SpawnError,
)
from twin_cli.loop import SteppingLoop, WorldLock
from twin_cli.pose import Pose
from twin_cli.queries import JointState
from twin_cli.scene import (
    INTEGRATORS,
    ODE_ONLY_FIELDS,
    SOLVERS,
    build_world_spec,
    solver_tolerance,
)
from twin_cli.world_types import (
    GRAVITY_PRESETS,
    EntityInfo,
    SpawnResult,
    Stats,
    WorldSettings,
    check_settings,
    finite_vector,
    scene_settings,
)

__all__ = [
    "GRAVITY_PRESETS",
    "EntityInfo",
    "JointState",
    "Pose",
    "SpawnResult",
    "Stats",
    "World",
    "WorldSettings",
]

_STATE = mujoco.mjtState.mjSTATE_INTEGRATION
WARNINGS_KEPT = 100  # MuJoCo warning texts kept in World.mujoco_warnings


class World:
    """A MuJoCo world with Gazebo's defaults, entities spawned by name, and a real-time loop."""

    def __init__(self, settings: WorldSettings | None = None, *, name: str = "default") -> None:
        self.settings = settings or WorldSettings()
        check_settings(self.settings)
        self.name = name
        self.lock = WorldLock()
        self._spec = build_world_spec(scene_settings(self.settings))
        self.model = self._spec.compile()
        self.model.opt.tolerance = solver_tolerance(self.model)
        self.data = mujoco.MjData(self.model)
        self._entities: dict[str, Entity] = {}
        self._index: dict[str, EntityIndex] = {}
        self._commands: dict[str, control.JointCommand] = {}
        self._pushes: list[control.Push] = []
        self._damping: control.Damping | None = None
        self._iterations = 0
        self._paused = False
        self.divergences = 0
        self.divergence_log: list[Divergence] = []
        self.mujoco_warnings: deque[str] = deque(maxlen=WARNINGS_KEPT)
        self._snapshot = np.empty(mujoco.mj_stateSize(self.model, _STATE))
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
    ) -> SpawnResult:
        """Adds an entity at `pose`; existing entities keep their exact state.

        The source is read (and converted) before the lock is taken, so a slow conversion does
        not stall the loop. The new entity starts at rest in its own initial configuration
        (its `home` key if it has one). Returns once the entity is in the world.

        Raises:
            EntityExistsError: `name` is taken. SpawnError: unreadable source or compile error.
            converters.ConversionError: the converter refused the file.
        """
        if name is not None:
            spawn.check_entity_name(name)
        loaded = spawn.load_source(source, args, package_paths)
        with self.lock:
            name = self._free_name(name, loaded.default_name)
            trial = self._spec.copy()
            try:
                home = spawn.prepare_child(loaded.spec, self._spec)
                spawn.attach(trial, loaded.spec, name, pose)
            except ValueError as exc:
                raise SpawnError(
                    name, loaded.source, f"cannot be attached ({exc})", "fix the model"
                ) from exc
            model, data, index = self._rebuild(trial, name, loaded.source)
            q = spawn.initial_qpos(model, index[name], home, pose)
            if on_ground:
                pose, q, (model, data, index) = self._ground(
                    trial, model, data, index, name, pose, q
                )
            state = rest_state(model, index[name], q)
            write_state(data, index[name], state)
            entity = Entity(
                name,
                loaded.source,
                dict(args or {}),
                dict(package_paths or {}),
                pose,
                on_ground,
                state,
                loaded.report,
                loaded.xml,
            )
            warnings = placement.start_warnings(model, data, index, name, pose.z)
            self._entities[name] = entity
            self._commit(trial, model, data, index)
            return SpawnResult(name, loaded.source, warnings, loaded.report)

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
            self._commit(trial, model, data, index)

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

    def _rebuild(
        self, trial: mujoco.MjSpec, new: str | None, source: str
    ) -> tuple[mujoco.MjModel, mujoco.MjData, dict[str, EntityIndex]]:
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
        names = [n for n in self._entities if n in self._index] + ([new] if new else [])
        index = index_entities(model, names)
        for n in self._entities:
            if n in self._index and n in index:
                write_state(data, index[n], capture_state(self.data, self._index[n]))
        data.time = self.data.time
        self._reapply_commands(model, data)
        return model, data, index

    def _ground(self, trial, model, data, index, name, pose, q):  # noqa: ANN001, ANN202
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
            q[int(np.flatnonzero(ix.qpos == ix.free_qpos)[0]) + 2] -= low
            return pose, q, (model, data, index)
        spawn.move_frame(trial, name, pose)
        model, data, index = self._rebuild(trial, name, "on-ground placement")
        return pose, model.qpos0[index[name].qpos].copy(), (model, data, index)

    def _commit(
        self,
        trial: mujoco.MjSpec,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        index: dict[str, EntityIndex],
    ) -> None:
        self._spec, self.model, self.data, self._index = trial, model, data, index
        model.opt.tolerance = solver_tolerance(model)
        self._snapshot = np.empty(mujoco.mj_stateSize(model, _STATE))
        self._damping = control.damping_of(model, element_names(model, model.name_numericadr))
        control.apply_pushes(model, data, self._pushes, {p.body for p in self._pushes})

    def _reapply_commands(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        for actuator, cmd in self._commands.items():
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)
            if a >= 0:
                control.apply_command(model, data, a, cmd)

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
            self.data.qpos[ix.free_qpos : ix.free_qpos + 3] = pose.position()
            self.data.qpos[ix.free_qpos + 3 : ix.free_qpos + 7] = pose.quat()
            self.data.qvel[ix.dofs] = 0.0
            self.data.qacc_warmstart[ix.dofs] = 0.0

    def joint_states(self, name: str) -> list[JointState]:
        """Position, velocity and actuator effort of each joint (free joint excluded)."""
        with self.lock:
            return queries.joint_states(self.model, self.data, self._require(name), f"{name}/")

    def link_poses(self, name: str) -> dict[str, Pose]:
        """World pose of each of the entity's bodies (links), by name without prefix."""
        with self.lock:
            return queries.link_poses(self.model, self.data, self._require(name), f"{name}/")

    def push(
        self,
        name: str,
        force: tuple[float, float, float] = (0.0, 0.0, 0.0),
        torque: tuple[float, float, float] = (0.0, 0.0, 0.0),
        *,
        link: str | None = None,
        duration: float = 0.1,
    ) -> None:
        """Applies a world-frame force [N] and torque [N m] at a link's centre of mass.

        Lasts `duration` [s] of sim time, rounded to whole steps (at least one); pushes on the
        same link add up. `link` defaults to the entity's root body.
        """
        wrench = finite_vector("push force and torque", [*force, *torque], 6)
        if not (math.isfinite(duration) and duration > 0):
            raise InvalidRequestError(
                "push duration", f"{duration} s is not positive", "give a duration > 0 s"
            )
        with self.lock:
            ix = self._require(name)
            body = self._link_name(name, ix, link)
            steps = max(1, round(duration / self.model.opt.timestep))
            self._pushes.append(control.Push(body, tuple(wrench), self._iterations + steps))
            control.apply_pushes(self.model, self.data, self._pushes, {body})

    def _link_name(self, name: str, ix: EntityIndex, link: str | None) -> str:
        links = [
            n.removeprefix(f"{name}/")
            for n in element_names(self.model, self.model.name_bodyadr[ix.bodies])
        ]
        if link is None and links:
            return f"{name}/{links[0]}"
        if link not in links:
            raise PartNotFoundError(name, "link", str(link), links)
        return f"{name}/{link}"

    def command(self, name: str, joint: str, *, mode: str, value: float) -> None:
        """Sets a joint's target: "position" [rad|m], "velocity" [rad/s|m/s] or "effort" [N m|N].

        Targets are clipped to the joint's range (position) and effort limit (effort); the
        position and velocity servos never exceed the effort limit (see twin_cli.control).
        """
        if mode not in control.MODES:
            raise InvalidRequestError(
                f"command mode [{mode}]", "unknown", f"use one of {', '.join(control.MODES)}"
            )
        if not math.isfinite(value):
            raise InvalidRequestError(
                f"command value for joint [{joint}]",
                f"{value} is not finite",
                "give a finite number",
            )
        with self.lock:
            ix = self._require(name)
            a, j = self._motor_of(name, ix, joint)
            key = element_names(self.model, self.model.name_actuatoradr[[a]])[0]
            old = self._commands.get(key)
            effort = old.effort if old else control.effort_limit(self.model, a)
            inertia = float(self.model.dof_M0[self.model.jnt_dofadr[j]])
            kp, kv = control.servo_gains(mode, effort, inertia, self.model.opt.timestep)
            target = control.clip_target(self.model, j, mode, value, effort)
            cmd = control.JointCommand(key, mode, target, kp, kv, effort)
            control.apply_command(self.model, self.data, a, cmd)
            self._commands[key] = cmd

    def _motor_of(self, name: str, ix: EntityIndex, joint: str) -> tuple[int, int]:
        m = self.model
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{name}/{joint}")
        actuated = {
            int(m.actuator_trnid[a][0]): int(a)
            for a in ix.actuators
            if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
        }
        if j < 0 or j not in actuated:
            known = [
                n.removeprefix(f"{name}/") for n in element_names(m, m.name_jntadr[list(actuated)])
            ]
            raise PartNotFoundError(name, "actuated joint", joint, known)
        return actuated[j], j

    # ----------------------------------------------------------------- gravity and physics
    def gravity(self) -> tuple[float, float, float]:
        """The gravity vector [m/s²]."""
        with self.lock:
            return tuple(float(v) for v in self.model.opt.gravity)  # type: ignore[return-value]

    def set_gravity(self, vector: tuple[float, float, float]) -> None:
        """Sets gravity [m/s²]; takes effect on the next step (see GRAVITY_PRESETS)."""
        g = finite_vector("gravity", vector, 3)
        with self.lock:
            self.model.opt.gravity[:] = g
            self._spec.option.gravity = g
            self.settings = replace(self.settings, gravity=tuple(g))

    def physics(self) -> dict:
        """Timestep [s], rate [Hz], iterations, solver, integrator, gravity, target factor, and
        the ODE-only fields Gazebo carries that MuJoCo has no counterpart for."""
        with self.lock:
            s = self.settings
            return {
                "timestep": s.timestep,
                "rate": s.rate,
                "iterations": s.iterations,
                "solver": s.solver,
                "integrator": s.integrator,
                "gravity": list(s.gravity),
                "target_factor": s.timestep * s.rate if s.rate > 0 else None,
                "not_applicable": list(ODE_ONLY_FIELDS),
            }

    def set_physics(
        self,
        *,
        timestep: float | None = None,
        rate: float | None = None,
        iterations: int | None = None,
        solver: str | None = None,
        integrator: str | None = None,
    ) -> dict:
        """Changes any of the physics settings (None keeps a value); returns `physics()`."""
        changes = {
            k: v
            for k, v in dict(
                timestep=timestep,
                rate=rate,
                iterations=iterations,
                solver=solver,
                integrator=integrator,
            ).items()
            if v is not None
        }
        with self.lock:
            new = replace(self.settings, **changes)
            check_settings(new)
            self.settings = new
            for target in (self.model.opt, self._spec.option):
                target.timestep, target.iterations = new.timestep, new.iterations
                target.solver, target.integrator = SOLVERS[new.solver], INTEGRATORS[new.integrator]
            self._damping = control.damping_of(
                self.model, element_names(self.model, self.model.name_numericadr)
            )
            self._loop.reanchor()
            return self.physics()

    # ----------------------------------------------------------------- run control
    @property
    def paused(self) -> bool:
        """Whether the real-time loop is paused (step() still works)."""
        return self._paused

    def pause(self) -> None:
        """Pauses the real-time loop."""
        with self.lock:
            self._paused = True

    def resume(self) -> None:
        """Resumes the real-time loop (the pacer re-anchors: no catch-up burst)."""
        with self.lock:
            self._paused = False
            self._loop.reanchor()

    def step(self, n: int = 1) -> None:
        """Steps `n` times now (paused or not)."""
        if not isinstance(n, int) or n < 0:
            raise InvalidRequestError(
                "step count", f"{n!r} is not a whole number >= 0", "give e.g. 100"
            )
        with self.lock:
            self._advance(n)

    def reset(self, *, time_only: bool = False) -> None:
        """Puts every entity back to its spawn state and time to 0 (or only time and iterations).

        A full reset also clears pushes and joint commands (motors back to zero effort).
        """
        with self.lock:
            if time_only:
                self._pushes = [
                    replace(p, end_step=p.end_step - self._iterations) for p in self._pushes
                ]
                self.data.time, self._iterations = 0.0, 0
                self._loop.reset_clock()
                return
            self._commands, self._pushes = {}, []
            model = self._spec.compile()
            data = mujoco.MjData(model)
            index = index_entities(model, list(self._entities))
            for n, e in self._entities.items():
                write_state(data, index[n], e.spawn_state)
            self._iterations = 0
            self._commit(self._spec, model, data, index)
            self._loop.reset_clock()

    def stats(self) -> Stats:
        """`gz stats` figures (factor averaged over the last 20 samples of 0.2 s)."""
        with self.lock:
            fig = self._loop.figures()
            return Stats(
                fig.factor, float(self.data.time), fig.real_time, self._iterations, self._paused
            )

    def loop_figures(self):  # noqa: ANN201
        """The loop's own measurements (factor, real time, lateness, dropped steps)."""
        return self._loop.figures()

    def start(self) -> None:
        """Starts the real-time stepping thread."""
        self._loop.start()

    def stop(self) -> None:
        """Stops and joins the stepping thread."""
        self._loop.stop()

    @property
    def running(self) -> bool:
        """Whether the stepping thread runs."""
        return self._loop.running

    def save(self, path: str | os.PathLike) -> None:
        """Writes entities, sources, settings and the full state to `path` (atomically)."""
        from twin_cli import worldfile

        with self.lock:
            worldfile.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> World:
        """A new, stopped world rebuilt from a file written by `save`."""
        from twin_cli import worldfile

        return worldfile.load(cls, path)

    # ----------------------------------------------------------------- stepping (lock held)
    def _loop_view(self) -> tuple[float, bool, float, int]:
        return self.settings.rate, self._paused, float(self.data.time), self._iterations

    def _advance(self, n: int) -> None:
        """Steps n times, splitting at push expiries; caller holds the lock."""
        while n > 0:
            due = min((p.end_step for p in self._pushes), default=None)
            chunk = n if due is None else max(1, min(n, due - self._iterations))
            self._step_chunk(chunk)
            n -= chunk
            if due is not None and self._iterations >= due:
                self._expire_pushes()

    def _step_chunk(self, n: int) -> None:
        """Steps n times; on divergence, replays the batch step by step to catch its origin.

        NaNs spread to other entities through collisions within a few steps, so a divergence
        found after a batch is traced back: the batch-start state is restored and stepped one
        step at a time, and the entity that goes bad first is reset to its spawn state.
        """
        m, d = self.model, self.data
        if n > 1:
            mujoco.mj_getState(m, d, self._snapshot, _STATE)
        before = warning_counts(d)
        # MuJoCo's default handler prints and appends to ./MUJOCO_LOG.TXT; keep its text instead.
        previous = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(self.mujoco_warnings.append)
        try:
            if self._damping is None:
                mujoco.mj_step(m, d, nstep=n)
            else:
                dofs, keep = self._damping.dofs, self._damping.keep
                for _ in range(n):
                    mujoco.mj_step(m, d)
                    d.qvel[dofs] *= keep
        finally:
            mujoco.set_mju_user_warning(previous)
        self._iterations += n
        bad = find_divergent(d, before, self._index)
        if bad and n == 1:
            self._recover(bad)
        elif bad:
            mujoco.mj_setState(m, d, self._snapshot, _STATE)
            self._iterations -= n
            for _ in range(n):
                self._step_chunk(1)

    def _recover(self, bad: dict[str, str]) -> None:
        """Resets the offending entities to their spawn state; the others keep their state.

        MuJoCo's auto-reset (which would reset the whole world) is disabled in every world
        spec (scene.apply_physics), so within one step a diverging entity's NaNs stay its own.
        """
        for name, reason in bad.items():
            write_state(self.data, self._index[name], self._entities[name].spawn_state)
            self.divergences += 1
            self.divergence_log.append(Divergence(name, float(self.data.time), reason))

    def _expire_pushes(self) -> None:
        ended = {p.body for p in self._pushes if p.end_step <= self._iterations}
        self._pushes = [p for p in self._pushes if p.end_step > self._iterations]
        control.apply_pushes(self.model, self.data, self._pushes, ended)
