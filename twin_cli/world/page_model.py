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


def plugin_free(spec: mujoco.MjSpec) -> mujoco.MjModel:
    """Compiles `spec` (a copy of the world's: it is changed) with its plugin actuators as
    integrators and no plugin instances."""
    for actuator in spec.actuators:
        if actuator.plugin.active:
            actuator.plugin.active = False
            actuator.plugin.name = actuator.plugin.plugin_name = ""
            actuator.dyntype = mujoco.mjtDyn.mjDYN_INTEGRATOR  # the activation slot it had
    for instance in list(spec.plugins):
        spec.delete(instance)
    return spec.compile()
