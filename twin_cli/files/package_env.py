"""The environment variables that steer package and model lookup (`$(find pkg)`, `package://`,
`model://`), which a client sends with a spawn.

A spawn converts on the server, whose environment is the one it started with; a user who
exported `ROS_PACKAGE_PATH` in another shell expects `twin spawn` to resolve packages as
`twin convert` does there. So the client sends its own values of these variables, the server
resolves with them, and the conversion cache keys on them. Light on purpose: client commands
import it.
"""

from __future__ import annotations

import os

PACKAGE_ENVS = (
    "ROS_PACKAGE_PATH",
    "AMENT_PREFIX_PATH",
    "GAZEBO_MODEL_PATH",
    "GZ_SIM_RESOURCE_PATH",
    "GZ_FUEL_CACHE_PATH",
    "IGN_GAZEBO_RESOURCE_PATH",
    "SDF_PATH",
    "GAZEBO_RESOURCE_PATH",
)


def package_env() -> dict[str, str]:
    """This process's values of PACKAGE_ENVS (unset ones left out)."""
    return {name: os.environ[name] for name in PACKAGE_ENVS if name in os.environ}


def package_roots(env: dict[str, str] | None = None) -> tuple[str, ...]:
    """The folders the PACKAGE_ENVS of `env` (default: this process's) name: where packages,
    models and their meshes may be found, and all a DDS peer's spawn may read."""
    values = package_env() if env is None else env
    roots: list[str] = []
    for name in PACKAGE_ENVS:
        for entry in values.get(name, "").split(os.pathsep):
            if entry and os.path.isabs(entry) and entry not in roots:
                roots.append(entry)
    return tuple(roots)
