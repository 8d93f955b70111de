"""The child side of a bounded conversion (`converters.isolated.bounded`): what runs after the fork.

It takes the caller's environment and folder (the fork server's are from its own start), limits
its address space, records the files it reads, runs the work and sends one message: the result
pickled, or the error by class name and text. It ends with its caller, and within SLACK_S of its
time budget in any case.
"""

from __future__ import annotations

import errno
import io
import os
import pickle
import sys
import threading
from collections.abc import Callable
from types import MappingProxyType
from typing import Any

from converters.errors import ConversionError
from converters.isolated import stages

READ_EVENT = "converters.read"
SLACK_S = 2.0  # [s] a child outlives its time budget by at most this much, caller or not
_CODE_SUFFIXES = (".py", ".pyc", ".so", ".zip", ".pth")
_WRITE_MODES = ("w", "a", "x", "+")


CHILD_NICENESS = 10
"""How much lower a conversion runs than the world that asked for it: on a busy machine a
conversion that takes all it can (a xacro bomb, a huge mesh) must not slow the stepping loop or
keep `twin stats` waiting (measured on 2 loaded cores at equal priority: 1.07-1.48 s)."""


def serve(
    send: Any,
    board: Any,
    work: Callable[[Any], Any],
    job: Any,
    budget: tuple[float, int],
    place: tuple[dict, str],
) -> None:
    """In the child: the caller's environment and folder (not the fork server's, which are
    from its start), limited memory, reads recorded; run `work`, send one final message."""
    import resource

    timeout_s, memory_mib = budget
    die_with_parent()
    _end_with_caller(send, timeout_s)
    os.nice(CHILD_NICENESS)  # the world's loop and its other requests come first
    os.environ.clear()
    os.environ.update(place[0])
    os.chdir(place[1])
    size = memory_mib * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (size, size))
    stages.share(board)
    files: set[str] = set()
    sys.addaudithook(_reads(files))
    try:
        message: tuple = ("done", dumps(work(job)))
    except ConversionError as exc:
        message = ("error", (type(exc).__name__, str(exc)))
    except MemoryError:
        message = ("memory",)
    except RecursionError:  # a description nested past what a reader recurses through
        problem = f"{stages.current()}: nests deeper than twin can follow; flatten the description"
        message = ("error", ("ConversionError", problem))
    except Exception as exc:  # a converter defect, unless memory ran out in another guise
        message = ("memory",) if _out_of_memory(exc) else ("crash", f"{type(exc).__name__}: {exc}")
    send.send((*message, sorted(files)) if message[0] != "memory" else message)


def _end_with_caller(send: Any, timeout_s: float) -> None:
    """End this child when its caller is gone or its time is up, whoever is still there.

    Its parent is the fork server, which outlives a killed caller while a child holds the
    server's "alive" pipe, so PR_SET_PDEATHSIG alone would leave a child working for nobody:
    a thread waits for the result pipe's reader to close (POLLERR on the write end), and the
    kernel ends the child SLACK_S after its budget (SIGALRM, default action), even inside C.
    """
    import select
    import signal

    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.setitimer(signal.ITIMER_REAL, timeout_s + SLACK_S)

    def watch() -> None:
        poller = select.poll()
        poller.register(send.fileno(), select.POLLERR)
        poller.poll()
        os._exit(1)

    threading.Thread(target=watch, name="twin-caller-watch", daemon=True).start()


def _out_of_memory(exc: BaseException) -> bool:
    """Whether `exc` (or its cause) is the address-space limit in another guise: an import
    whose library cannot be mapped, an OSError ENOMEM."""
    seen: BaseException | None = exc
    while seen is not None:
        text = str(seen).lower()
        if isinstance(seen, OSError) and seen.errno == errno.ENOMEM:
            return True
        if "failed to map segment" in text or "cannot allocate memory" in text:
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def dumps(value: Any) -> bytes:
    """Pickle `value`; read-only mappings (the description's) travel as dicts made read-only."""
    buffer = io.BytesIO()
    pickler = pickle.Pickler(buffer, protocol=pickle.HIGHEST_PROTOCOL)
    pickler.dispatch_table = {MappingProxyType: _reduce_proxy}
    pickler.dump(value)
    return buffer.getvalue()


def _reduce_proxy(proxy: MappingProxyType) -> tuple:
    return read_only, (dict(proxy),)


def read_only(mapping: dict) -> MappingProxyType:
    """A read-only view of `mapping` (how a pickled `MappingProxyType` is rebuilt)."""
    return MappingProxyType(mapping)


def _reads(files: set[str]) -> Callable[[str, tuple], None]:
    """An audit hook adding files opened for reading (not code) to `files`."""
    code_dirs = tuple({sys.prefix, sys.base_prefix, sys.exec_prefix})

    def hook(event: str, args: tuple) -> None:
        if event == READ_EVENT:
            files.add(os.fsdecode(args[0]))
            return
        if event != "open" or not isinstance(args[0], (str, bytes, os.PathLike)):
            return
        mode = args[1]
        if isinstance(mode, str) and any(m in mode for m in _WRITE_MODES):
            return
        if isinstance(mode, int) and mode & (os.O_WRONLY | os.O_RDWR):
            return
        name = os.path.abspath(os.fsdecode(args[0]))
        if not name.endswith(_CODE_SUFFIXES) and not name.startswith(code_dirs):
            files.add(name)

    return hook


def die_with_parent() -> None:
    """Ask the kernel to kill this process when the one that started it ends (Linux)."""
    try:
        import ctypes
        import signal

        ctypes.CDLL("libc.so.6").prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() == 1:  # the parent ended before the request took effect
        os._exit(1)
