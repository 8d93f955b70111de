"""Runs one scenario in an in-process World: builds the world, spawns the robot, applies actions.

Physics checks read measurements through `ScenarioRun` (under the world's lock) and never talk
to MuJoCo's stepping directly: the same engine as `twin serve`, without the server.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from twin_cli.spawn_request import SpawnRequest
from twin_cli.validate.checks.base import CannotApply, RobotUnderTest
from twin_cli.validate.checks.model_joints import HINGE, SLIDE, joint_effort
from twin_cli.validate.scenario import Action, Obstacle, Scenario

PLANE = 0  # mjtGeom mjGEOM_PLANE
NO_BODY = "the robot has no body that can move (an MJCF with only world geoms): nothing to simulate"


@dataclass(frozen=True)
class RobotJoint:
    """One 1-DoF joint of the spawned robot: world ids, its effort limit [N m] or [N] and its
    declared velocity limit [rad/s] or [m/s] (None: not declared)."""

    name: str
    joint: int
    qpos: int
    dof: int
    effort: float | None
    velocity: float | None = None


def obstacle_spec(box: Obstacle, name: str):
    """A static box (no joint: welded to the world) with Gazebo μ on its surface."""
    import mujoco

    spec = mujoco.MjSpec()
    spec.modelname = name
    body = spec.worldbody.add_body(name="box")
    geom = body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[s / 2.0 for s in box.size],
        friction=[box.mu, 0.005, 0.0001],
    )
    try:
        from converters.gazebo.contact import friction_priority

        geom.priority = friction_priority(box.mu)
    except ImportError:  # converter's contact module not installed yet: MuJoCo's max rule
        pass
    return spec


class ScenarioRun:
    """A World built from a scenario with the robot spawned in it.

    Attributes:
        world: the `twin_cli.world.engine.World`.
        entity: the robot's entity name.
        bodies: world body ids of the robot; `root` is its root body.
        joints: the robot's 1-DoF joints.
        time: simulated time since the start [s].
    """

    def __init__(self, robot: RobotUnderTest, scenario: Scenario, *, observed: bool = True) -> None:
        """Build the world and spawn the robot; `observed` False leaves it unfilmed and
        unrecorded (`--video`, `--record`), for a run whose stepping is being timed."""
        from twin_cli.world import Pose, World, WorldSettings

        w = scenario.world
        settings = WorldSettings(
            timestep=w.timestep, rate=w.rate, gravity=w.gravity_vector(), ground=w.ground
        )
        self.scenario = scenario
        self.world: World = World(settings, name=f"validate-{scenario.name}")
        pose = Pose(**scenario.robot.pose.model_dump())
        spawned = self.world.spawn(
            SpawnRequest(
                robot.spec.copy(),
                on_ground=scenario.robot.on_ground,
                joints=dict(scenario.robot.joints),
            ),
            name=robot.name,
            pose=pose,
        )
        self.entity = spawned.name
        self._velocity_limits = {j.name: j.velocity for j in robot.declared_joints}
        self._index_robot()
        for i, box in enumerate(scenario.obstacles):
            self._spawn_obstacle(box, f"obstacle{i}")
        self.forward()
        self.time = 0.0
        self.q_hold = self.qpos()[[j.qpos for j in self.joints]].copy()
        self.kp, self.kd = self._hold_gains()
        if observed:
            from twin_cli.validate import video
            from twin_cli.validate.recording import attach

            attach(self.world, scenario.name)  # `twin validate --record DIR`
            video.film(self.world, self.entity)  # `twin validate --video`: a no-op otherwise

    def _index_robot(self) -> None:
        from twin_cli.world.velocity_motors import is_rotor  # mujoco: scenario parsing stays light

        model = self.world.model
        prefix = f"{self.entity}/"
        self.bodies = [b for b in range(model.nbody) if model.body(b).name.startswith(prefix)]
        if not self.bodies:
            raise CannotApply(NO_BODY)
        self.root = min(self.bodies)
        self.joints = [
            RobotJoint(
                model.joint(j).name.removeprefix(prefix),
                j,
                int(model.jnt_qposadr[j]),
                int(model.jnt_dofadr[j]),
                joint_effort(model, j),
                self._velocity_limits.get(model.joint(j).name.removeprefix(prefix)),
            )
            for j in range(model.njnt)
            if int(model.jnt_bodyid[j]) in self.bodies
            and int(model.jnt_type[j]) in (HINGE, SLIDE)
            and not is_rotor(model.joint(j).name)
        ]
        self.mass = float(sum(model.body_mass[b] for b in self.bodies))
        self.floating = any(
            int(model.jnt_type[j]) == 0 and int(model.jnt_bodyid[j]) == self.root
            for j in range(model.njnt)
        )

    def _spawn_obstacle(self, box: Obstacle, name: str) -> None:
        from twin_cli.world import Pose

        pose = box.pose.model_dump()
        self.forward()
        if box.ahead_gap is not None:
            pose["x"] = self.extent()[1][0] + box.ahead_gap + box.size[0] / 2.0
        self.world.spawn(obstacle_spec(box, name), name=name, pose=Pose(**pose))
        self._index_robot()  # ids may shift after a recompile

    def forward(self) -> None:
        """Recompute positions, COMs and contacts of the current state (the state is unchanged)."""
        import mujoco

        with self.world.lock:
            mujoco.mj_forward(self.world.model, self.world.data)

    # ---- measurements (world ids; read under the lock) -------------------------------------
    def qpos(self) -> np.ndarray:
        with self.world.lock:
            return np.array(self.world.data.qpos)

    def subtree_com(self) -> np.ndarray:
        """The robot's centre of mass [m] in the world frame."""
        with self.world.lock:
            return np.array(self.world.data.subtree_com[self.root])

    def robot_geoms(self) -> list[int]:
        model = self.world.model
        return [g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in self.bodies]

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds [m] (min xyz, max xyz) of the robot's geoms' bounding spheres
        (of its links' centres of mass when it has no geom at all)."""
        with self.world.lock:
            data, model = self.world.data, self.world.model
            geoms = self.robot_geoms()
            if geoms:
                centres = np.array([data.geom_xpos[g] for g in geoms])
                radii = np.array([model.geom_rbound[g] for g in geoms])[:, None]
            else:
                centres = np.array([data.xipos[b] for b in self.bodies])
                radii = np.zeros((len(self.bodies), 1))
        return (centres - radii).min(axis=0), (centres + radii).max(axis=0)

    def ground_contacts(self) -> list[tuple[int, float]]:
        """(robot geom, signed distance [m]) of every robot contact with the ground plane."""
        with self.world.lock:
            model, data = self.world.model, self.world.data
            out = []
            for i in range(data.ncon):
                c = data.contact[i]
                pair = (int(c.geom1), int(c.geom2))
                planes = [g for g in pair if int(model.geom_type[g]) == PLANE]
                mine = [g for g in pair if int(model.geom_bodyid[g]) in self.bodies]
                if planes and mine:
                    out.append((mine[0], float(c.dist)))
            return out

    def warnings(self) -> int:
        """Total MuJoCo warnings raised so far (instability, NaN, contact overflow...)."""
        with self.world.lock:
            return int(sum(w.number for w in self.world.data.warning))

    # ---- running -----------------------------------------------------------------------------
    def run(
        self,
        duration: float,
        on_sample: Callable[[ScenarioRun], None] | None = None,
        every: int = 10,
    ) -> None:
        """Step `duration` [s], applying the scenario's actions; call `on_sample` every N steps."""
        dt = float(self.world.model.opt.timestep)
        steps = int(round(duration / dt))
        pushes = [a for a in self.scenario.actions if a.kind in ("push", "torque")]
        per_step = self.scenario.hold is not None or any(
            a.kind == "drive" for a in self.scenario.actions
        )
        chunk = 1 if per_step else every
        done = 0
        while done < steps:
            for action in pushes:
                # Half-step windows: sim time accumulates rounding (0.1 + … != 0.6), and an
                # action at an exact multiple of the step must fall in exactly one window.
                start = self.time - 0.5 * dt
                if start <= action.at < start + chunk * dt:
                    self._push(action)
            if per_step:
                self._apply_joint_forces()
            n = min(chunk, steps - done)
            self.world.step(n)
            done += n
            self.time += n * dt
            if on_sample and (done % every == 0 or done == steps):
                on_sample(self)

    def _push(self, action: Action) -> None:
        force = action.force or (0.0, 0.0, 0.0)
        if action.force_per_kg is not None:
            force = tuple(v * self.mass for v in action.force_per_kg)
        self.world.push(
            self.entity,
            force=tuple(force),
            torque=tuple(action.torque or (0.0, 0.0, 0.0)),
            link=action.link,
            duration=action.duration,
        )

    def joint_torques(self) -> np.ndarray:
        """Hold (PD to the start posture) plus active drives, clipped to each joint's effort."""
        hold = self.scenario.hold
        with self.world.lock:
            q = np.array([self.world.data.qpos[j.qpos] for j in self.joints])
            qd = np.array([self.world.data.qvel[j.dof] for j in self.joints])
        tau = np.zeros(len(self.joints))
        if hold is not None:
            tau = self.kp * (self.q_hold - q) - self.kd * qd
        for action in self.scenario.actions:
            if action.kind == "drive" and action.at <= self.time < action.at + action.duration:
                for i, joint in enumerate(self.joints):
                    if action.joints == "*" or joint.name in action.joints:
                        tau[i] = _drive_value(action, joint)
        return np.array(
            [gazebo_effort(t, v, j) for t, v, j in zip(tau, qd, self.joints, strict=True)]
        )

    def _hold_gains(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-joint PD gains of the hold, capped so the explicit PD stays stable.

        A PD applied once per step h on a joint of effective inertia I is stable only for
        kd·h/I < 2 and kp·h²/I < 1; the caps keep a margin of 4 (kd ≤ I/(2h), kp ≤ I/(4h²)),
        so 300 N m/rad holds a humanoid hip but not a 40 g leg. I is what a torque at the joint
        accelerates, 1/(M⁻¹)ᵢᵢ: on a floating robot the torque also turns the base, so I is
        below the mass matrix's diagonal Mᵢᵢ (solo12's knee: 2.2e-4 vs 5.4e-4 kg m²; capping
        with Mᵢᵢ made its stance diverge within 25 ms).
        """
        hold = self.scenario.hold
        if hold is None or not self.joints:
            return np.zeros(len(self.joints)), np.zeros(len(self.joints))
        h = float(self.world.model.opt.timestep)
        inertia = self._effective_inertia()
        kp = np.minimum(hold.kp, inertia / (4.0 * h * h))
        kd = np.minimum(hold.kd, inertia / (2.0 * h))
        return kp, kd

    def _effective_inertia(self) -> np.ndarray:
        """1/(M⁻¹)ᵢᵢ [kg m² or kg] of each joint at the current state."""
        import mujoco

        with self.world.lock:
            model, data = self.world.model, self.world.data
            full = np.zeros((model.nv, model.nv))
            mujoco.mj_fullM(model, data, full)  # MuJoCo 4 signature: (m, d, dst)
        inverse = np.linalg.inv(full)
        return np.array([1.0 / inverse[j.dof, j.dof] for j in self.joints])

    def _apply_joint_forces(self) -> None:
        tau = self.joint_torques()
        self.world.set_joint_forces([j.dof for j in self.joints], list(tau))

    def close(self) -> None:
        """Release the world (no thread runs; nothing else to free)."""
        # a closed run is never used again: dropping the world frees it
        self.world = None  # pyright: ignore[reportAttributeAccessIssue]


def gazebo_effort(tau: float, qvel: float, joint: RobotJoint) -> float:
    """The effort Gazebo applies for a commanded `tau` (gazebo-classic `Joint::SetForce` →
    `CheckAndTruncateForce`): zero when the joint already moves faster than its velocity
    limit in the direction of `tau`, then clipped to ±effort.

    Without the velocity rule a full-effort drive spins ANYmal's ±3π rad knee to 400 rad/s
    (velocity limit 7.5 rad/s) and whirls the whole robot.

    Args:
        tau: commanded effort [N m] or [N].
        qvel: joint velocity [rad/s] or [m/s].
        joint: the joint, with its effort and velocity limits.
    """
    limit = joint.velocity
    if limit is not None and limit >= 0.0 and abs(qvel) > limit and tau * qvel > 0.0:
        tau = 0.0
    effort = joint.effort if joint.effort is not None else math.inf
    return min(max(tau, -effort), effort)


def _drive_value(action: Action, joint: RobotJoint) -> float:
    effort = joint.effort or 0.0
    if action.effort == "max":
        return effort
    if action.effort == "min":
        return -effort
    return float(action.effort)
