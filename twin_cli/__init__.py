"""twin's world engine, server, client and command line.

Importing this package imports nothing heavy: mujoco is imported by the modules that step physics
(world, validate), never by the client or the CLI commands that only talk to a server.
"""

__all__: list[str] = []
