"""What the web viewer's page asks of the world, done through the World's API.

MuJoCo's viewer handle would act on the `MjData` it is given: Reset calls `mj_resetData`, the
Options panel overwrites `model.opt`, Ctrl+drag overwrites all of `data.xfrc_applied` every frame,
and a dropped file replaces the model. On a twin world that would happen behind the engine's back
(pushes erased, `twin physics` out of date, entities not back at their spawn poses). `WorldBridge`
is a sim-side plugin whose handlers run first (USER priority), do the same through `World`
(pause/resume/step/reset/set_gravity/set_physics/perturb) and consume the message, so the
handle's own handlers never see it. It also tells the page when the world was paused or resumed
from the CLI, so the page's Run/Pause button shows the truth.
"""

from __future__ import annotations

import copy
import logging
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np
from mujoco.studio import messages, plugin, sim

from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli.world.entities import element_names

if TYPE_CHECKING:
    from twin_cli.world.engine import World

log = logging.getLogger("twin.view")

# The page's Options panel edits mjOption; the fields `World.set_physics` owns are these (by
# MuJoCo enum value → twin's name). Other fields the page edits are put back by the next sync,
# which sends the world's options whenever they differ from what the page was last sent.
SOLVER_NAMES = {int(v): k for k, v in SOLVERS.items()}
INTEGRATOR_NAMES = {int(v): k for k, v in INTEGRATORS.items()}


class WorldBridge(plugin.SimPlugin):
    """Routes the page's Pause/Run, step, Reset, options and perturbation to a World.

    Its handlers run inside `ViewerHandle.sync`, which the sync thread calls with the world's
    (re-entrant) lock held, so each World call below takes the lock it already holds.
    """

    def __init__(self, world: World) -> None:
        self.world = world
        self._paused_shown: bool | None = None
        self._perturbed = False

    # ------------------------------------------------------------------ run control
    @messages.handler(priority=messages.Priority.USER)
    def _on_step_control(self, event: messages.StepControlSnapshot) -> bool:
        paused = event.pause_state != sim.PauseState.UNPAUSED
        if paused != self.world.paused:
            log.info("viewer: %s", "pause" if paused else "run")
            self.world.pause() if paused else self.world.resume()
        self._paused_shown = paused
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_request_pause(self, event: messages.RequestPauseEvent) -> bool:
        paused = event.pause_state != sim.PauseState.UNPAUSED
        self.world.pause() if paused else self.world.resume()
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_single_step(self, _: messages.SingleStepEvent) -> bool:
        self.world.step(1)
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_reset(self, _: messages.ResetEvent) -> bool:
        """Reset is `twin reset`: every entity back at its spawn state, time 0."""
        log.info("viewer: reset")
        self.world.reset()
        return True

    # ------------------------------------------------------------------ settings
    @messages.handler(priority=messages.Priority.USER)
    def _on_options(self, event: messages.MjOptionSnapshot) -> bool:
        """Gravity, timestep, iterations, solver and integrator go through the World."""
        opt, now = event.opt, self.world.model.opt
        if not np.array_equal(opt.gravity, now.gravity):
            self.world.set_gravity(tuple(float(g) for g in opt.gravity))
        changes: dict[str, Any] = {}
        if opt.timestep != now.timestep:
            changes["timestep"] = float(opt.timestep)
        if opt.iterations != now.iterations:
            changes["iterations"] = int(opt.iterations)
        if opt.solver != now.solver:
            changes["solver"] = SOLVER_NAMES.get(int(opt.solver))
        if opt.integrator != now.integrator:
            changes["integrator"] = INTEGRATOR_NAMES.get(int(opt.integrator))
        changes = {k: v for k, v in changes.items() if v is not None}
        if changes:
            try:
                self.world.set_physics(**changes)
            except Exception as exc:  # a bad value from the page must not stop the viewer
                log.warning("viewer: physics change %s refused: %s", changes, exc)
        # What the world now runs with, so fields it does not take are put back on the page.
        self.handle.send_to_viewer(messages.MjOptionSnapshot(opt=copy.deepcopy(now)))
        return True

    # ------------------------------------------------------------------ perturbation
    @messages.handler(priority=messages.Priority.USER)
    def _on_perturb(self, snapshot: messages.PerturbSnapshot) -> bool:
        """The drag's wrench per body, added to `twin push` forces by the engine."""
        model = self.world.model
        if snapshot.state_sig != int(mujoco.mjtState.mjSTATE_XFRC_APPLIED):
            return True
        if len(snapshot.state) != model.nbody * 6:
            return True  # built for a model from before a spawn or delete
        wrenches = np.asarray(snapshot.state).reshape(model.nbody, 6)
        bodies = np.flatnonzero(np.any(wrenches != 0.0, axis=1))
        if not len(bodies) and not self._perturbed:
            return True  # the page sends zeros every frame while nothing is dragged
        names = element_names(model, model.name_bodyadr[bodies])
        self.world.perturb({n: wrenches[b] for n, b in zip(names, bodies, strict=True)})
        self._perturbed = bool(len(bodies))
        return True

    # ------------------------------------------------------------------ refused
    @messages.handler(priority=messages.Priority.USER)
    def _on_state(self, _: messages.StateEvent) -> bool:
        """Joint sliders and paused drags would write qpos behind the engine: ignored."""
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_load_model(self, _: messages.LoadModelEvent) -> bool:
        """A dropped file or Reload would replace the world's model: use `twin spawn`."""
        log.info("viewer: model load from the page ignored; use twin spawn")
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_keyframe(self, _: messages.KeyframeEvent) -> bool:
        return True

    @messages.handler(priority=messages.Priority.USER)
    def _on_threadpool(self, _: messages.ThreadPoolEvent) -> bool:
        return True

    # ------------------------------------------------------------------ world → page
    def show_pause_state(self) -> None:
        """Sends the world's pause state when it differs from what the page shows."""
        paused = bool(self.world.paused)
        if paused == self._paused_shown:
            return
        self._paused_shown = paused
        state = sim.PauseState.NORMAL_PAUSED if paused else sim.PauseState.UNPAUSED
        self.handle.send_to_viewer(messages.StepControlSnapshot(pause_state=state))
