"""World commands (Gazebo's verbs on a running world), one keyword-only function each.

Each module registers its functions with `twin_cli.cli.registry.command`; the registry imports
every module of this package, so a new module needs no list. Each function checks its values
(`BadOption`), makes its client calls through `world_client.connect_world` and prints through
`Output`. Client-side only: no mujoco, numpy, fastapi or typer (an import contract holds it).
"""

# `twin --help` lists the world commands in this order; one it does not name comes after them.
ORDER = (
    "stop",
    "spawn",
    "delete",
    "list",
    "pose",
    "joints",
    "push",
    "gravity",
    "physics",
    "pause",
    "resume",
    "step",
    "reset",
    "stats",
    "save",
    "load",
    "logs",
)
