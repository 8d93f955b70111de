"""twin's runtime errors (world, server, client, validation), each with its fix in the message."""

from __future__ import annotations


class TwinError(Exception):
    """Base class for errors of running worlds and of the CLI; exit code 2 at the boundary."""


class NotRunningError(TwinError):
    """No world server answers for this world name."""

    def __init__(self, world: str) -> None:
        super().__init__("An instance of twin is not running.")
        self.world = world


class EntityNotFoundError(TwinError):
    """A command named an entity the world does not have."""

    def __init__(self, name: str, known: list[str]) -> None:
        names = ", ".join(sorted(known)) or "none"
        super().__init__(f"Entity [{name}] does not exist; entities in this world: {names}")
        self.name = name


class EntityExistsError(TwinError):
    """Spawn with a name that is taken (Gazebo's wording)."""

    def __init__(self, name: str) -> None:
        super().__init__(
            f"Entity [{name}] already exists; choose another --name or delete it first"
        )
        self.name = name
