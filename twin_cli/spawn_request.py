"""One spawn as a value: what to read, how to read it and how to start it, CLI to saved entity.

A `SpawnRequest` is built once (by the CLI, a test, a world file or a save file) and travels
unchanged through the client, the HTTP body and the world into the entity's record, from which
`twin save` writes it and `twin load` spawns it again. Where an entity goes and what it is
called (`name`, `pose`) are per instance, so a batch of instances shares one request.
Standard library only: client commands import it.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

XML_LABEL = "<xml>"  # how a description given as text is named in messages and listings


@dataclass(frozen=True)
class SpawnRequest:
    """What one spawn needs besides the entity's name and pose.

    Attributes:
        source: the description file (URDF, xacro, SDF or MJCF), or an `mujoco.MjSpec` (a world
            file's model, a test's model); None when `xml` gives the description as text.
        xml: the description as text (SpawnEntity's `xml`, `twin spawn -` from stdin).
        base_dir: where relative mesh paths in `xml` start (the client's working directory).
        args: xacro arguments, name → value (`--arg name:=value`).
        package_paths: package name → directory (`--package NAME=PATH`).
        env: the client's package search variables (`twin_cli.files.package_env`); None: the
            server's own.
        joints: initial joint positions by joint name [rad] or [m] (`-J`, Gazebo's
            `spawn_model -J`).
        on_ground: lower the entity until its lowest collision point rests on z = 0.
        repair_inertia: bound non-physical inertias instead of refusing the file.
        strict: refuse Gazebo and control tags that name a missing link or joint, and
            visuals whose mesh is missing, instead of leaving them out with a warning (Gazebo's
            behaviour).
        fixed_base: weld the root link to the world at the spawn pose (no free joint), as a
            `world` link and a fixed joint do; a robot already fixed is unchanged.
        coacd_cpu_limit: CPU time CoACD may spend on one collision mesh before its hull stands
            in [CPU s]; None: the converting process's default (`twin serve --coacd-cpu-limit`).
        read_roots: the only folders the spawn may read (a DDS peer's request: the world's
            package and model paths); None: wherever the server's user may. Not saved: a
            saved world is loaded by its user.
    """

    source: Any = None
    xml: str | None = None
    base_dir: str | None = None
    args: Mapping[str, str] = field(default_factory=dict)
    package_paths: Mapping[str, str] = field(default_factory=dict)
    env: Mapping[str, str] | None = None
    joints: Mapping[str, float] = field(default_factory=dict)
    on_ground: bool = False
    repair_inertia: bool = False
    strict: bool = False
    fixed_base: bool = False
    coacd_cpu_limit: float | None = None
    read_roots: tuple[str, ...] | None = None

    @property
    def label(self) -> str:
        """How the source is named in messages: the path as given, or `<xml>`."""
        if self.xml is not None:
            return XML_LABEL
        if isinstance(self.source, (str, Path)):
            return str(self.source)
        return "<MjSpec>"

    def absolute(self) -> SpawnRequest:
        """Paths made absolute against this process's working directory (the server has its
        own working directory, so a client resolves them before sending)."""
        source = self.source
        if isinstance(source, (str, Path)):
            source = str(Path(source).expanduser().absolute())
        base_dir = self.base_dir
        if self.xml is not None:
            base_dir = str(Path(base_dir or ".").expanduser().absolute())
        packages = {k: str(Path(v).expanduser().absolute()) for k, v in self.package_paths.items()}
        return replace(self, source=source, base_dir=base_dir, package_paths=packages)

    def options(self) -> dict[str, Any]:
        """How to read and start the source, in JSON form (everything but the source)."""
        return {
            "args": dict(self.args),
            "package_paths": dict(self.package_paths),
            "env": None if self.env is None else dict(self.env),
            "joints": dict(self.joints),
            "on_ground": self.on_ground,
            "repair_inertia": self.repair_inertia,
            "strict": self.strict,
            "fixed_base": self.fixed_base,
            "coacd_cpu_limit": self.coacd_cpu_limit,
        }

    def to_body(self) -> dict[str, Any]:
        """The JSON form: the HTTP request body's fields.

        Raises:
            TypeError: the source is an MjSpec, which has no JSON form (send its MJCF as `xml`).
        """
        if self.xml is not None:
            return {"xml": self.xml, "base_dir": self.base_dir, **self.options()}
        if self.source is not None and not isinstance(self.source, (str, Path)):
            raise TypeError("an MjSpec source has no JSON form; give its MJCF text as xml")
        return {"source": None if self.source is None else str(self.source), **self.options()}

    @classmethod
    def from_body(cls, body: Mapping[str, Any]) -> SpawnRequest:
        """The request from its JSON form (missing fields take their defaults; a
        `drop_dangling` of older clients and saves is the default now, and is not read)."""
        return cls(
            source=body.get("source"),
            xml=body.get("xml"),
            base_dir=body.get("base_dir"),
            args=dict(body.get("args") or {}),
            package_paths=dict(body.get("package_paths") or {}),
            env=None if body.get("env") is None else dict(body["env"]),
            joints={k: float(v) for k, v in (body.get("joints") or {}).items()},
            on_ground=bool(body.get("on_ground", False)),
            repair_inertia=bool(body.get("repair_inertia", False)),
            strict=bool(body.get("strict", False)),
            fixed_base=bool(body.get("fixed_base", False)),
            coacd_cpu_limit=_optional_float(body.get("coacd_cpu_limit")),
        )


def _optional_float(value: Any) -> float | None:
    return None if value is None else float(value)


def as_request(source: SpawnRequest | Any) -> SpawnRequest:
    """A request as it is, or a bare source (a path or an MjSpec) as a request with defaults."""
    return source if isinstance(source, SpawnRequest) else SpawnRequest(source=source)


def body_key(method: str, path: str, body: Any) -> str:
    """An idempotency identity for a request: equal exactly for equal requests.

    Two spawns of one file that differ in anything (pose, names, args, the description text)
    are different operations; a repeat of the same command line is the same one.
    """
    canonical = json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(f"{method} {path} {canonical}".encode()).hexdigest()
