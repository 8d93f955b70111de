"""xacro in a process of its own, with a time and memory budget and no access beyond the robot.

xacro is a programming language: `${9**9**9}` computes for ever while holding the interpreter
lock, 2^25 nested macro calls fill memory, `xacro.load_yaml('/any/file')` and `$(env VAR)` read
whatever the process can. A server that expanded xacro in its own process froze with its world
and lent its files and environment to every description. So a served conversion expands xacro in
a child process:
- it is killed when it passes its time budget (wall clock) or memory budget (address space),
  and the error says which budget and how to raise it;
- its environment holds only the variables the spawning client sent (`$(env)`, `$(optenv)`);
- it may open for reading only files under the description's own folder, the packages it names
  and the package roots of those variables (plus Python's own files); anything else is refused
  with a message that names the path and never shows its content;
- it dies with the server (PR_SET_PDEATHSIG), so a stopped world leaves no child computing.
The files it read are announced with the audit event `converters.read`, so a conversion cache
that watches what a conversion read sees them too.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

from converters.errors import ConversionError, XacroBudgetError, XacroError, rebuilt_error
from converters.isolated.bounded_child import CHILD_NICENESS, READ_EVENT, die_with_parent
from converters.isolated.budget import MEMORY_ENV, TIMEOUT_ENV, XacroBudget
from converters.resources.packages import PackageResolver
from converters.urdf.xacro_expand import XacroResult


def expand_bounded(
    path: Path, args: dict[str, str], resolver: PackageResolver, budget: XacroBudget
) -> XacroResult:
    """`expand_xacro` in a child process under `budget` (see the module docstring).

    Raises:
        XacroBudgetError: the expansion passed its time or memory budget.
        XacroError, PackageNotFoundError, …: what the expansion raised, as the same class.
    """
    request = {
        "memory_mib": budget.memory_mib,
        "path": str(path),
        "args": args,
        "packages": {name: str(directory) for name, directory in resolver.explicit.items()},
        "sys_path": sys.path,
    }
    env = {k: v for k, v in resolver.env.items() if k in _SENT}
    child = subprocess.Popen(
        [sys.executable, "-c", _BOOT],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**env, "OPENBLAS_NUM_THREADS": "1"},  # numpy's pools would eat the address space
    )
    _RUNNING.add(child)
    try:
        out, err = child.communicate(json.dumps(request), timeout=budget.timeout_s)
    except subprocess.TimeoutExpired as exc:
        child.kill()
        child.communicate()
        raise XacroBudgetError(str(path), f"took over {budget.timeout_s:g} s", TIMEOUT_ENV) from exc
    finally:
        _RUNNING.discard(child)
    if _STOPPING.is_set():
        raise XacroError(str(path), "stopped: the world is shutting down", "spawn it again")
    return _result(
        path, subprocess.CompletedProcess(child.args, child.returncode, out, err), budget
    )


def stop_all() -> None:
    """Kill every expansion still running (a server shutting down: its requests must end).

    For a process that is ending: from then on every served expansion in it fails at once.
    """
    _STOPPING.set()
    for child in list(_RUNNING):
        child.kill()


_RUNNING: set[subprocess.Popen] = set()  # children expanding right now (for `stop_all`)
_STOPPING = threading.Event()

# Package search variables: the only environment a served xacro sees (the client sends them).
_SENT = ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH", "GAZEBO_MODEL_PATH", "GZ_SIM_RESOURCE_PATH")
_SENT += ("GZ_FUEL_CACHE_PATH", "GAZEBO_RESOURCE_PATH")

# The child limits its own address space first thing (a preexec_fn is not safe in a threaded
# server), then reads its request.
_BOOT = (
    "import json, resource, sys; request = json.loads(sys.stdin.read()); "
    "size = request['memory_mib'] * 1024 * 1024; "
    "resource.setrlimit(resource.RLIMIT_AS, (size, size)); sys.path[:] = request['sys_path']; "
    "from converters.urdf.xacro_worker import serve; serve(request)"
)


def _result(path: Path, done: subprocess.CompletedProcess, budget: XacroBudget) -> XacroResult:
    """The child's answer, or its error raised again as the same class."""
    try:
        answer = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        if "MemoryError" in done.stderr or done.returncode < 0:
            problem = f"needed more than {budget.memory_mib} MiB"
            raise XacroBudgetError(str(path), problem, MEMORY_ENV) from None
        detail = done.stderr.strip().splitlines()[-1:] or [f"exit code {done.returncode}"]
        raise XacroError(str(path), detail[0][-300:], "fix the xacro file") from None
    for name in answer.get("files", []):
        sys.audit(READ_EVENT, name)
    if "error" in answer:
        raise rebuilt_error(answer["error"], answer["message"])
    return XacroResult(answer["text"], tuple(answer["unexpanded"]), tuple(answer["warnings"]))


# ----------------------------------------------------------------------------- the child
def serve(request: dict[str, Any]) -> None:
    """The child's work: expand, print one JSON line (the result or the error) on stdout."""
    from converters.urdf.xacro_expand import expand_xacro

    die_with_parent()
    os.nice(CHILD_NICENESS)  # the world's loop and its other requests come first
    path = Path(request["path"])
    resolver = PackageResolver.create(path, request["packages"], dict(os.environ))
    import xacro  # noqa: F401 (loaded before the guard: Python's own files stay readable)

    files: set[str] = set()
    refused: list[str] = []
    sys.addaudithook(_guard(_allowed_roots(path, resolver), files, refused))
    try:
        result = expand_xacro(path, request["args"], resolver)
        answer: dict[str, Any] = {
            "text": result.text,
            "unexpanded": list(result.unexpanded),
            "warnings": list(result.warnings),
        }
    except ConversionError as exc:
        # xacro may bury a refusal under an error of its own: the refusal is the cause.
        error = XacroError(str(path), refused[0], REFUSED_FIX) if refused else exc
        answer = {"error": type(error).__name__, "message": str(error)}
    answer["files"] = sorted(files)
    sys.stdout.write(json.dumps(answer) + "\n")


def _allowed_roots(path: Path, resolver: PackageResolver) -> tuple[str, ...]:
    """Where the description may read: its package (the nearest folder above it with a
    `package.xml`; without one, only its own folder), the packages given with --package or
    named by the client's variables, and Python's own installation."""
    resolved = path.resolve()
    package = next((d for d in resolved.parents if (d / "package.xml").is_file()), None)
    roots = [package if package is not None else resolved.parent]
    roots += [Path(p).resolve() for p in resolver.explicit.values()]
    for variable in _SENT:
        roots += [Path(p).resolve() for p in os.environ.get(variable, "").split(os.pathsep) if p]
    return tuple(str(r) for r in roots) + tuple(os.path.realpath(p) for p in _python_roots())


def _python_roots() -> set[str]:
    """Where Python's own files and the packages the expansion imports live: the prefixes, the
    site folders and the folders holding `converters` and `xacro`. Not every `sys.path` entry:
    a server started with `python -m` from a home folder has that folder there, and a xacro
    could then read anything under it."""
    import site

    import xacro

    import converters

    folders = {sys.prefix, sys.base_prefix, sys.exec_prefix, site.getusersitepackages()}
    folders |= set(site.getsitepackages())
    for package in (converters, xacro):
        folders.add(str(Path(package.__file__ or "").resolve().parent.parent))
    return folders


REFUSED_FIX = (
    "a served description may only read its own package (the folder with its package.xml); "
    "twin convert reads freely"
)
_PACKAGE_FILES = ("package.xml", "model.config")  # what `$(find)` reads to name a package
# What an expression could do besides reading a file; none of it is xacro's business.
_FORBIDDEN = (
    "subprocess.Popen", "os.system", "os.exec", "os.posix_spawn", "os.spawn", "os.fork",
    "os.forkpty", "os.kill", "os.killpg", "ctypes.dlopen", "ctypes.dlsym", "socket.connect",
    "socket.bind", "socket.sendto", "os.remove", "os.rename",
    "os.rmdir", "os.mkdir", "os.chmod", "os.chown", "os.symlink", "os.link", "shutil.rmtree",
)  # fmt: skip


def _guard(roots: tuple[str, ...], files: set[str], refused: list[str]) -> Any:
    """An audit hook refusing what a description has no business doing: starting processes,
    opening sockets, listing folders, writing, and reading outside `roots` (and the packages
    `$(find)` found so far). Records the files read, and each refusal."""
    from converters.urdf.xacro_expand import FOUND

    def refuse(what: str) -> None:
        refused.append(what)
        raise PermissionError(f"{what}; {REFUSED_FIX}")

    def hook(event: str, args: tuple) -> None:
        if event in _FORBIDDEN:
            refuse(f"an expression tried {event}, which a description may not do")
        if event in ("os.listdir", "os.scandir"):  # imports list folders: only allowed ones
            listed = os.path.realpath(os.fsdecode(args[0] if args[0] is not None else "."))
            if not _inside(listed, (*roots, *FOUND.get({}).values())):
                refuse(f"{listed} is outside the robot's own package")
            return
        if event != "open" or not isinstance(args[0], (str, bytes, os.PathLike)):
            return
        name = os.path.realpath(os.fsdecode(args[0]))
        mode, flags = args[1], args[2] if len(args) > 2 else 0
        writing = (isinstance(mode, str) and any(m in mode for m in "wax+")) or (
            isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR)
        )
        if writing:
            refuse(f"{name} was opened for writing, which a description may not do")
        metadata = os.path.basename(name) in _PACKAGE_FILES  # the package search reads them
        if not metadata and not _inside(name, (*roots, *FOUND.get({}).values())):
            refuse(f"{name} is outside the robot's own package")
        if os.path.isfile(name) and not name.endswith((".py", ".pyc", ".so")):
            files.add(name)

    return hook


def _inside(name: str, roots: tuple[str, ...]) -> bool:
    """Whether the resolved path `name` is one of `roots` or below one."""
    for root in roots:
        real = os.path.realpath(root)
        if name == real or name.startswith(real.rstrip(os.sep) + os.sep):
            return True
    return False
