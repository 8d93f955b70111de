"""The world's model as a browser's MuJoCo can load it.

MuJoCo's web viewer runs its own MuJoCo build, compiled without the engine's plugin libraries.
A model that uses one (a gz-sim PID with an integral runs on MuJoCo's `mujoco.pid` actuator,
`converters.mjcf.export_servos`) stops that page at its first `mj_forward` ("invalid plugin
slot"). The page draws the world; the world's process steps it. So the page gets a copy in which
each plugin actuator is a plain actuator with the same one activation, compiled from the
world's spec: the same bodies, geoms and state sizes, so the world's state loads into it. The
world's own model, its physics and its exported file keep the plugin.
"""

from __future__ import annotations

import mujoco


def plugin_free(spec: mujoco.MjSpec, model: mujoco.MjModel) -> mujoco.MjModel:
    """`model` itself when it uses no plugin, else a copy compiled from `spec` (the spec `model`
    was compiled from) with its plugin actuators as integrators and no plugin instances."""
    if model.nplugin == 0:
        return model
    shown = spec.copy()
    for actuator in shown.actuators:
        if actuator.plugin.active:
            actuator.plugin.active = False
            actuator.plugin.name = actuator.plugin.plugin_name = ""
            actuator.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR  # the activation slot it had
    for instance in list(shown.plugins):
        shown.delete(instance)
    page = shown.compile()
    refresh(page, model)
    return page


IN_PLACE = ("body_pos", "body_quat", "geom_rgba", "light_pos", "light_dir", "light_active")
"""What the world changes in its model in place that the page draws (a static entity moved,
lights), copied into the page's model at every sync with the options."""


def refresh(page: mujoco.MjModel, model: mujoco.MjModel) -> None:
    """Copies the world's options and `IN_PLACE` arrays of `model` into `page`."""
    page.opt = model.opt
    for name in IN_PLACE:
        getattr(page, name)[:] = getattr(model, name)
