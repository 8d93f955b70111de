"""twin's runtime errors (world, server, client, validation), each with its fix in the message."""

from __future__ import annotations


class TwinError(Exception):
    """Base class for errors of running worlds and of the CLI; exit code 2 at the boundary."""


class NotRunningError(TwinError):
    """No world server answers for this world name.

    The message starts with gz's readiness-probe line (scripts grep it) and names how to start
    a server for that world; like every failed client command it exits 2.
    """

    exit_code = 2
    MESSAGE = "An instance of twin is not running."

    def __init__(self, world: str, detail: str = "") -> None:
        first = f"{self.MESSAGE} {start_fix(world)}"
        super().__init__(f"{first}\n{detail}" if detail else first)
        self.world = world
        self.detail = detail


def start_fix(world: str) -> str:
    """How to start a server for `world` (the default world needs no --world)."""
    import shlex

    flag = "" if world == "default" else f" --world {shlex.quote(world)}"
    return (
        f"Start one with `twin serve{flag}` (in the foreground) or `twin spawn FILE{flag}` "
        "(in the background)."
    )


class EntityNotFoundError(TwinError):
    """A command named an entity the world does not have."""

    def __init__(self, name: str, known: list[str]) -> None:
        names = ", ".join(sorted(known)) or "none"
        fix = "give one of those names (`twin list`)" if known else "spawn one with `twin spawn`"
        super().__init__(f"Entity [{name}] does not exist; entities in this world: {names}; {fix}")
        self.name = name


class EntityExistsError(TwinError):
    """Spawn with a name that is taken (Gazebo's wording)."""

    def __init__(self, name: str) -> None:
        super().__init__(
            f"Entity [{name}] already exists; choose another --name or delete it first"
        )
        self.name = name


class WorldRunningError(TwinError):
    """`twin serve` for a world whose server already runs (one server per world name)."""

    def __init__(self, world: str, pid: int | None) -> None:
        who = f" (pid {pid})" if pid else ""
        super().__init__(
            f"world [{world}] is already served{who}; use it, stop it with "
            f"`twin stop --world {world}`, or serve another --world"
        )
        self.world = world


class ServerStartError(TwinError):
    """A background world server did not come up."""

    def __init__(self, world: str, log: object, problem: str) -> None:
        super().__init__(
            f"world server [{world}] failed to start: {problem}; see its log {log} "
            f"(`twin logs --world {world}`)"
        )
        self.world = world


class RequestError(TwinError):
    """The server refused a request as malformed, or failed on it with an unexpected error."""

    def __init__(self, what: str, problem: str, fix: str) -> None:
        super().__init__(f"{what}: {problem}; {fix}")
        self.what = what


class ScenarioError(TwinError):
    """A scenario file (TOML) is malformed or names something that does not exist."""

    def __init__(self, path: object, key: str, problem: str, fix: str) -> None:
        where = f"{path}: {key}" if key else f"{path}"
        super().__init__(f"{where}: {problem}; {fix}")
        self.path = path
        self.key = key


class UnknownCheckError(TwinError):
    """--only/--skip or a scenario named a validation check that does not exist."""

    def __init__(self, name: str, known: list[str]) -> None:
        super().__init__(
            f"unknown validation check [{name}]; valid checks: {', '.join(sorted(known))}"
        )
        self.name = name


class SpawnError(TwinError):
    """A spawn failed (unreadable source, compile error); the world is left as it was."""

    def __init__(self, entity: str, source: str, problem: str, fix: str) -> None:
        super().__init__(f"spawn of [{entity}] from {source}: {problem}; {fix}")
        self.entity = entity
        self.source = source


class InvalidRequestError(TwinError):
    """A world request carries a bad value (non-finite gravity, unknown solver, bad mode...)."""

    def __init__(self, what: str, problem: str, fix: str) -> None:
        super().__init__(f"{what}: {problem}; {fix}")
        self.what = what


class ModeNotOfferedError(InvalidRequestError):
    """A joint command in a mode none of the joint's command interfaces offers: no ros2_control
    controller could claim it, so twin refuses it rather than drive the joint another way."""

    TAG_SOURCES = ("ros2_control", "transmission")

    def __init__(
        self, entity: str, joint: str, mode: str, offered: tuple[str, ...], source: str
    ) -> None:
        kinds = source.split("+")
        tagged = all(k in self.TAG_SOURCES for k in kinds)
        # a plugin's record (diff_drive, multicopter_motor_model) is no tag a user can extend
        who = " and ".join(f"<{k}>" for k in kinds) + " tags" if tagged else f"{source} plugin"
        why = f"its {who} offer{'' if tagged else 's'} only {', '.join(offered)}"
        fix = f"use --mode {' or '.join(offered)}"
        if not offered:  # a MuJoCo plugin twin does not know reads ctrl its own way
            why = f"its {who} reads ctrl its own way, so twin writes none"
            fix = "drive the joint through an actuator without a plugin"
        elif tagged:
            fix += (
                f', or declare {mode} for it (<command_interface name="{mode}"/> in its '
                f"<ros2_control> joint, or a <transmission> with hardware_interface/"
                f"{mode.capitalize()}JointInterface), then delete the entity and spawn it again"
            )
        super().__init__(f"{mode} command for joint [{joint}] of [{entity}]", why, fix)
        self.offered = offered


class PartNotFoundError(TwinError):
    """A request named a joint or link that the entity does not have."""

    def __init__(self, entity: str, kind: str, name: str, known: list[str]) -> None:
        names = ", ".join(sorted(known)) or "none"
        super().__init__(f"entity [{entity}] has no {kind} [{name}]; its {kind}s: {names}")
        self.entity = entity
        self.name = name


class TopicNotFoundError(TwinError):
    """`twin topics echo` named a topic the running world does not offer."""

    def __init__(self, name: str, known: list[str]) -> None:
        names = ", ".join(known) or "none"
        super().__init__(
            f"topic [{name}] is not offered by this world; its topics: {names} "
            "(`twin topics` lists them with types and rates)"
        )
        self.name = name


class WorldFileError(TwinError):
    """A saved world file cannot be read, or no longer matches its sources."""

    def __init__(self, path: object, problem: str, fix: str) -> None:
        super().__init__(f"{path}: {problem}; {fix}")
        self.path = path


class NoReplyError(TwinError):
    """A request got no reply in time: the server may still be doing it."""

    # sysexits' EX_TEMPFAIL, as OutcomeUnknownError: not bad input, not a bug.
    exit_code = 75

    def __init__(self, world: str, what: str, waited: float) -> None:
        super().__init__(
            f"{what} on world [{world}]: no reply within {waited:g} s, so the outcome is unknown "
            f"(the server may be busy); check with `twin stats --world {world}` and "
            "`twin logs`, then try again"
        )
        self.world = world


class OutcomeUnknownError(TwinError):
    """A spawn or delete got no reply within the client's patience: it may still happen."""

    # sysexits' EX_TEMPFAIL: not bad input (2), not a bug (70); trying again is the remedy.
    exit_code = 75

    def __init__(self, world: str, what: str, waited: float, repeat: str) -> None:
        super().__init__(
            f"{what} on world [{world}]: no reply within {waited:g} s, so the outcome is unknown "
            f"(the world may still be doing it); check with `twin list --world {world}`, or "
            f"repeat `{repeat}`: a repeat is safe, it gets this request's outcome; "
            "set TWIN_TIMEOUT (s) to wait longer"
        )
        self.world = world


class OffscreenUnavailableError(TwinError):
    """No offscreen OpenGL for `twin snapshot` or `twin validate --video`."""

    def __init__(self, problem: str) -> None:
        super().__init__(
            f"offscreen rendering is not available ({problem}); install Mesa's EGL "
            "(Debian/Ubuntu: `apt-get install libegl-mesa0 libgl1-mesa-dri`) and run with "
            "MUJOCO_GL=egl (the world server sets it when unset)"
        )
