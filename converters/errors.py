"""Conversion errors: each names what is wrong, where (file, link, joint) and the fix."""

from __future__ import annotations


class ConversionError(Exception):
    """Base class for every error a description file can cause.

    Subclasses take the facts as arguments and build the message, so that every
    message says what, where and how to fix it.
    """


class InputFileError(ConversionError):
    """The input file is missing, unreadable or of an unknown format."""

    def __init__(self, path: str, problem: str, fix: str) -> None:
        super().__init__(f"{path}: {problem}; {fix}")
        self.path = path


class OutputDirError(ConversionError):
    """The model's output folder cannot be written (read-only, full, a mount point, ...)."""

    def __init__(self, path: str, problem: str) -> None:
        super().__init__(
            f"{path}: cannot write the model there ({problem}); choose another folder with -o"
        )
        self.path = path


class GazeboTagError(ConversionError):
    """A `<gazebo>` tag (or inline `<surface>` value) that cannot be read."""

    def __init__(self, source: str, reference: str, tag: str, value: str, expected: str) -> None:
        where = f"<gazebo reference='{reference}'>" if reference else "<gazebo> (model)"
        super().__init__(
            f"{source}: {where} <{tag}>: value {value!r} is not {expected}; "
            f"write {expected} (e.g. <{tag}>{_gazebo_example(expected)}</{tag}>)"
        )
        self.source = source
        self.reference = reference
        self.tag = tag
        self.value = value


def _gazebo_example(expected: str) -> str:
    examples = {
        "a number": "0.5",
        "a number ≥ 0": "0.5",
        "a number > 0": "1e5",
        "an integer": "10",
        "three numbers": "1 0 0",
        "a finite number": "0.5",
        "a finite number >= 0": "0.5",
        "a number below cmd_max": "-1000",
        "0 (encoder) or 1 (world)": "1",
        "a wheel joint name": "wheel_left_joint",
    }
    return examples.get(expected, "true")


class PluginJointError(ConversionError):
    """A plugin names a joint the model does not have."""

    def __init__(self, source: str, plugin: str, tag: str, joint: str, joints: list[str]) -> None:
        valid = ", ".join(joints) or "none"
        where = f" in <{tag}>" if tag else ""
        super().__init__(
            f"{source}: <plugin> '{plugin}' names joint '{joint}'{where}, which the model does "
            f"not have; name one of its joints ({valid})"
        )
        self.source = source
        self.joint = joint


# --- Converter core: packages, xacro, URDF structure, inertia, meshes -----------------------


class PackageNotFoundError(ConversionError):
    """A `$(find pkg)`, `package://` or `model://` names a package found nowhere."""

    def __init__(self, package: str, uri: str, element: str, tried: list[str]) -> None:
        places = "\n  ".join(tried) or "(no search paths)"
        kind, variable = (
            ("model", "GAZEBO_MODEL_PATH")
            if uri.startswith("model://")
            else (
                "package",
                "ROS_PACKAGE_PATH",
            )
        )
        super().__init__(
            f"{kind} '{package}' not found for {uri!r} used by {element}; tried:\n  {places}\n"
            f"fix: pass --package {package}=PATH or add its parent directory to {variable}"
        )
        self.package = package
        self.uri = uri


class OutsideRootsError(ConversionError):
    """A confined conversion (a DDS peer's spawn) opened a file outside its folders."""

    def __init__(self, path: str, roots: tuple[str, ...]) -> None:
        shown = ", ".join(r.rstrip("/") for r in roots[:4]) or "none"
        super().__init__(
            f"{path}: outside the folders a spawn over DDS may read (the world's package and "
            f"model paths: {shown}); put it on GZ_SIM_RESOURCE_PATH or ROS_PACKAGE_PATH before "
            "`twin serve`, or spawn it with `twin spawn`"
        )
        self.path = path


class ResourceNotAFileError(ConversionError):
    """A mesh or included file resolves to something that is not a regular file (a device, a
    directory): reading it would never end or fail."""

    def __init__(self, uri: str, element: str, path: str) -> None:
        super().__init__(
            f"{uri!r} used by {element} resolves to {path}, which is not a regular file (a "
            "device or a directory); point it at a mesh or model file"
        )
        self.uri = uri
        self.path = path


class ResourceNotFoundError(ConversionError):
    """A mesh or included file resolves to a path that does not exist."""

    def __init__(self, uri: str, element: str, path: str) -> None:
        super().__init__(
            f"{uri!r} used by {element} resolves to {path}, which does not exist; "
            "fix the filename or the package location (--package NAME=PATH)"
        )
        self.uri = uri
        self.path = path


class XacroError(ConversionError):
    """xacro failed on the input; carries xacro's own message."""

    def __init__(self, path: str, message: str, fix: str | None = None) -> None:
        fix = fix or "fix the xacro file or pass the missing argument with --arg NAME:=VALUE"
        super().__init__(f"{path}: xacro failed: {message}; {fix}")
        self.path, self.detail, self.fix = path, message, fix


class XacroBudgetError(ConversionError):
    """A served xacro expansion passed its time or memory budget and was stopped."""

    def __init__(self, path: str, problem: str, variable: str) -> None:
        super().__init__(
            f"{path}: xacro expansion {problem}, its budget, and was stopped; if the robot really "
            f"needs more, start the world with a larger {variable} (twin stop; "
            f"{variable}=... twin spawn ...)"
        )
        self.path = path


class ConversionBudgetError(ConversionError):
    """A served conversion passed its time or memory budget and was stopped."""

    def __init__(self, path: str, stage: str, problem: str, variable: str) -> None:
        super().__init__(
            f"{path}: conversion {problem}, its budget, while {stage}, and was stopped; if the "
            f"robot really needs more, start the world with a larger {variable} (twin stop; "
            f"{variable}=... twin spawn ...), or convert it once with `twin convert` and spawn "
            "the MJCF it writes"
        )
        self.path = path
        self.stage = stage


class ConversionStoppedError(ConversionError):
    """A served conversion was stopped because its world is shutting down."""

    def __init__(self, path: str) -> None:
        super().__init__(f"{path}: conversion stopped: the world is shutting down; spawn it again")
        self.path = path


class MalformedXMLError(ConversionError):
    """The description is not well-formed XML."""

    def __init__(self, path: str, line: int, column: int, message: str) -> None:
        super().__init__(f"{path}:{line}:{column}: malformed XML: {message}; fix the XML there")
        self.path = path
        self.line = line
        self.column = column


class URDFStructureError(ConversionError):
    """The link/joint graph is not a tree: unknown links, cycles, several roots, duplicates."""

    def __init__(self, path: str, subject: str, problem: str, fix: str) -> None:
        super().__init__(f"{path}: {subject}: {problem}; {fix}")
        self.path = path
        self.subject = subject


class BadNumberError(ConversionError):
    """An attribute that must hold numbers does not."""

    def __init__(self, path: str, element: str, attribute: str, value: str, expected: str) -> None:
        super().__init__(
            f"{path}: {element}: attribute {attribute}={value!r} is not {expected}; "
            "write plain decimal numbers (xacro expressions must be expanded)"
        )
        self.path = path
        self.element = element


class InertiaError(ConversionError):
    """A moving link has no, or a non-physical, mass/inertia."""

    REPAIRABLE = (
        "give it a physical <inertial> (mass > 0, positive-definite tensor, ixx+iyy >= izz etc.) "
        "or pass --repair-inertia"
    )

    def __init__(
        self, path: str, link: str, problem: str, values: str, fix: str = REPAIRABLE
    ) -> None:
        super().__init__(f"{path}: link '{link}': {problem} ({values}); {fix}")
        self.path = path
        self.link = link


class MeshError(ConversionError):
    """A mesh file exists but cannot be loaded or is unusable."""

    def __init__(self, path: str, link: str, problem: str) -> None:
        super().__init__(f"mesh {path} of link '{link}': {problem}; export it again as STL/OBJ/DAE")
        self.path = path
        self.link = link


class CollisionSettingsError(ConversionError):
    """A collision option names an unknown mode or preset, or contradicts another option."""

    def __init__(self, option: str, value: str, valid: list[str]) -> None:
        super().__init__(
            f"collision option {option}: {value!r} is not valid; use one of: {', '.join(valid)}"
        )
        self.option = option
        self.value = value


class SDFError(ConversionError):
    """An SDFormat file that twin cannot read: names file:line, the element and the fix."""

    def __init__(self, path: str, line: int | None, element: str, problem: str, fix: str) -> None:
        where = f"{path}:{line}" if line else path
        super().__init__(f"{where}: {element}: {problem}; {fix}")
        self.path = path
        self.line = line
        self.element = element


class DanglingReferenceError(ConversionError):
    """Gazebo or control tags name a link or joint the robot does not have."""

    def __init__(self, source: str, problems: list[str], names: list[str]) -> None:
        shown = ", ".join(names[:30]) + (f" (+{len(names) - 30} more)" if len(names) > 30 else "")
        super().__init__(
            f"{source}: {'; '.join(problems)}; name one of its links or joints ({shown}), or "
            "convert without --strict to leave these out with a warning, as Gazebo does"
        )
        self.source = source
        self.problems = problems


class MissingVisualMeshError(ConversionError):
    """With `--strict`: visuals whose mesh file or package is missing (Gazebo draws nothing)."""

    def __init__(self, source: str, problems: list[str]) -> None:
        super().__init__(
            f"{source}: " + "\n".join(problems) + "\nor convert without --strict to leave "
            "these visuals out with a warning, as Gazebo does"
        )
        self.source = source
        self.problems = problems


def rebuilt_error(name: str, text: str) -> ConversionError:
    """A child process's error as the same class, from its class name and text (the classes'
    constructors take facts, so they cannot be pickled through a pipe)."""
    cls = globals().get(name)
    if not (isinstance(cls, type) and issubclass(cls, ConversionError)):
        cls = ConversionError
    exc = cls.__new__(cls)
    Exception.__init__(exc, text)
    return exc
