"""Driving a World's entities: world-frame pushes on links and joint targets for motors.

A mixin of `twin_cli.world.engine.World` (it uses the world's lock, model, data, index, pushes and
commands); the servo and push arithmetic lives in `twin_cli.world.actuation`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco

from twin_cli.errors import InvalidRequestError, PartNotFoundError
from twin_cli.world import actuation as control
from twin_cli.world.entities import EntityIndex, element_names
from twin_cli.world.values import finite_vector


class EntityControl:
    """Pushes and joint commands (mixin; see module docstring)."""

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
            control.apply_pushes(self.model, self.data, self._pushes, {body}, self._perturbation)

    def perturb(self, wrenches: dict[str, Sequence[float]]) -> None:
        """Sets a viewer's mouse perturbation: world-frame wrench [N, N m] per full body name.

        Replaces the previous perturbation (a drag is re-sent every frame; `{}` ends it) and is
        added to the pushes of `push` on the same body, never written over them. Unknown bodies
        are ignored (the viewer may still show a model from before a spawn or delete).
        """
        wrench = {b: tuple(finite_vector("perturbation", w, 6)) for b, w in wrenches.items()}
        with self.lock:
            touched = set(self._perturbation) | set(wrench)
            self._perturbation = wrench
            control.apply_pushes(self.model, self.data, self._pushes, touched, wrench)

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
        position and velocity servos never exceed the effort limit (see twin_cli.world.actuation).
        """
        _check_command(joint, mode, value)
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

    def _reapply_commands(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """Writes every joint command into a (re)compiled model, by actuator name."""
        for actuator, cmd in self._commands.items():
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)
            if a >= 0:
                control.apply_command(model, data, a, cmd)


def _check_command(joint: str, mode: str, value: float) -> None:
    if mode not in control.MODES:
        raise InvalidRequestError(
            f"command mode [{mode}]", "unknown", f"use one of {', '.join(control.MODES)}"
        )
    if not math.isfinite(value):
        raise InvalidRequestError(
            f"command value for joint [{joint}]", f"{value} is not finite", "give a finite number"
        )
