"""One resolver for `$(find pkg)`, `package://`, `model://`, `file://` and relative paths."""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from converters.errors import (
    ConversionError,
    PackageNotFoundError,
    ResourceNotAFileError,
    ResourceNotFoundError,
)
from converters.resources.fuel import fuel_caches, fuel_file, is_web_uri
from converters.resources.package_exports import MEDIA_PATH, MODEL_PATH, exported_paths

# Environment variables searched, in order, as ROS 1 / ROS 2 / Gazebo users set them.
ROS_ENV = "ROS_PACKAGE_PATH"
AMENT_ENV = "AMENT_PREFIX_PATH"
# Where a model (`model://NAME`, or an include's scheme-less `NAME`) is looked for, in order:
# gz-sim's resource paths (and Ignition's name for them), libsdformat's SDF_PATH, Gazebo
# Classic's model path; then the `gazebo_model_path` exports of ROS packages.
MODEL_ENVS = ("GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH", "SDF_PATH", "GAZEBO_MODEL_PATH")
# Where Gazebo looks for a relative `file://` resource after the model's own directory; then
# the `gazebo_media_path` exports of ROS packages.
RESOURCE_ENVS = ("GAZEBO_RESOURCE_PATH", "GZ_SIM_RESOURCE_PATH")

_PACKAGE_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")


def package_xml_name(directory: Path) -> str | None:
    """The `<name>` declared by `directory/package.xml`, or None if there is none."""
    try:
        text = (directory / "package.xml").read_text(errors="replace")
    except OSError:
        return None
    match = _PACKAGE_NAME.search(text)
    return match.group(1) if match else None


def _split_env(value: str | None) -> list[Path]:
    return [Path(p) for p in (value or "").split(os.pathsep) if p]


@dataclass(frozen=True)
class PackageResolver:
    """Finds packages and resource files without ROS.

    Search order for a package name: explicit `--package NAME=PATH` entries, `ROS_PACKAGE_PATH`
    (each entry a package or a directory of packages), `AMENT_PREFIX_PATH` (`<prefix>/share/<pkg>`),
    for `model://` also the model roots (`model_roots`: the Gazebo and SDFormat path variables,
    then ROS packages' `gazebo_model_path` exports), then the directories above the input file
    (one whose package.xml names the package, one named like it, or a sibling).

    Attributes:
        explicit: package name → directory, from `--package` options.
        input_file: the robot description being converted (its ancestors are searched last).
        env: environment snapshot (defaults to `os.environ` at construction).
    """

    explicit: Mapping[str, Path] = field(default_factory=dict)
    input_file: Path | None = None
    env: Mapping[str, str] = field(default_factory=lambda: dict(os.environ))
    _cache: dict[str, list[Path]] = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def create(
        cls,
        input_file: str | Path | None,
        package_paths: Mapping[str, str | Path] | None = None,
        env: Mapping[str, str] | None = None,
    ) -> PackageResolver:
        """Build a resolver from user options (paths made absolute)."""
        explicit = {k: Path(v).expanduser().resolve() for k, v in (package_paths or {}).items()}
        source = Path(input_file).resolve() if input_file is not None else None
        return cls(explicit, source, dict(os.environ if env is None else env))

    def _candidates(self, name: str, model: bool) -> list[Path]:
        """Every directory that could be package `name`, in search order."""
        out: list[Path] = []
        if name in self.explicit:
            out.append(self.explicit[name])
        for entry in _split_env(self.env.get(ROS_ENV)):
            out += [entry, entry / name]
        out += [prefix / "share" / name for prefix in _split_env(self.env.get(AMENT_ENV))]
        if model:
            out += [root / name for root in self.model_roots()]
        if self.input_file is not None:
            for ancestor in self.input_file.parents:
                out += [ancestor, ancestor / name]
        return out

    def model_roots(self) -> list[Path]:
        """Directories Gazebo models are looked for in (`MODEL_ENVS`, then the
        `gazebo_model_path` exports of the ROS packages on the package paths), in order."""
        roots = [entry for var in MODEL_ENVS for entry in _split_env(self.env.get(var))]
        return roots + self._exported(MODEL_PATH)

    def _exported(self, attribute: str) -> list[Path]:
        """Paths ROS packages export for Gazebo (`package_exports`), read once per resolver."""
        if attribute not in self._cache:
            ros = tuple(_split_env(self.env.get(ROS_ENV)))
            ament = tuple(_split_env(self.env.get(AMENT_ENV)))
            self._cache[attribute] = exported_paths(ros, ament, attribute)
        return self._cache[attribute]

    def find_package(
        self, name: str, *, uri: str = "", element: str = "", model: bool = False
    ) -> Path:
        """Directory of package `name`.

        Args:
            name: package (or Gazebo model) name.
            uri: the URI being resolved, for the error message.
            element: the element that used it (e.g. "link 'base' <mesh>"), for the message.
            model: also search the Gazebo model paths (for `model://`).

        Raises:
            PackageNotFoundError: naming the URI, the element and every place tried.
        """
        tried: list[str] = []
        for candidate in self._candidates(name, model):
            if self._is_package(candidate, name):
                return candidate
            tried.append(str(candidate))
        raise PackageNotFoundError(
            name, uri or f"$(find {name})", element or "the description", tried
        )

    @staticmethod
    def _is_package(candidate: Path, name: str) -> bool:
        if not candidate.is_dir():
            return False
        declared = package_xml_name(candidate)
        return declared == name or candidate.name == name

    def resolve(self, uri: str, *, base_dir: Path, element: str, must_exist: bool = True) -> Path:
        """The absolute file a URI or path names.

        Args:
            uri: `package://pkg/rel`, `model://name/rel`, `file://path`, absolute or relative path.
            base_dir: directory relative paths are taken from (the description's directory).
            element: who used the URI, for error messages.
            must_exist: raise if the resolved file does not exist.

        Raises:
            PackageNotFoundError: the package is unknown.
            ResourceNotFoundError: the resolved file does not exist.
        """
        path = self._locate(uri.strip(), base_dir, element)
        if must_exist and path.exists() and not path.is_file():
            raise ResourceNotAFileError(uri, element, str(path))
        if must_exist and not path.is_file():
            tried = [path, *self._resource_paths(uri.strip())]
            found = next((p for p in tried[1:] if p.is_file()), None)
            if found is not None:
                return found
            if len(tried) > 1:
                raise ResourceSearchError(uri, element, [str(p) for p in tried])
            raise ResourceNotFoundError(uri, element, str(path))
        return path

    def _resource_paths(self, uri: str) -> list[Path]:
        """A relative `file://` URI under each Gazebo resource path entry, as Gazebo Classic
        (`GAZEBO_RESOURCE_PATH`) and Gazebo (`GZ_SIM_RESOURCE_PATH`) look it up."""
        if not uri.startswith("file://") or Path(uri[len("file://") :]).is_absolute():
            return []
        relative = uri[len("file://") :]
        entries = [e for var in RESOURCE_ENVS for e in _split_env(self.env.get(var))]
        entries += self._exported(MEDIA_PATH)
        return [entry / relative for entry in entries]

    def _locate(self, uri: str, base_dir: Path, element: str) -> Path:
        for scheme, model in (("package://", False), ("model://", True)):
            if uri.startswith(scheme):
                name, _, rest = uri[len(scheme) :].partition("/")
                root = self.find_package(name, uri=uri, element=element, model=model)
                return root / rest
        if is_web_uri(uri):
            cached = fuel_file(uri, self.env)
            if cached is None:
                raise WebResourceError(uri, element, fuel_caches(self.env))
            return cached
        if uri.startswith("file://"):
            uri = uri[len("file://") :]
        path = Path(uri).expanduser()
        return path if path.is_absolute() else (base_dir / path).resolve()


class ResourceSearchError(ResourceNotFoundError):
    """A relative `file://` resource found neither beside its file nor on a resource path."""

    def __init__(self, uri: str, element: str, tried: list[str]) -> None:
        places = "\n  ".join(tried)
        ConversionError.__init__(
            self,
            f"{uri!r} used by {element} was found nowhere; tried:\n  {places}\n"
            f"fix: the filename, or add the directory it is under to {RESOURCE_ENVS[0]}",
        )
        self.uri = uri
        self.path = tried[0]
        self.tried = tried


class WebResourceError(ResourceNotFoundError):
    """A resource named by a web address: a Gazebo Fuel model's file the local Fuel cache
    lacks, or another site's (gz-sim downloads both; twin never does)."""

    def __init__(self, uri: str, element: str, caches: list[Path]) -> None:
        ConversionError.__init__(
            self,
            f"{uri!r} used by {element} is on the web and not in the local Fuel cache "
            f"({', '.join(str(c) for c in caches)}); twin does not download\n"
            f"fix: run `gz fuel download -u '{uri.split('/files/')[0]}'` where there is "
            "internet, or copy the file beside the description and name it by a relative path",
        )
        self.uri = uri
        self.path = uri
