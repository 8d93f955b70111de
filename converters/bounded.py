"""Work on a description in a child process the caller can bound: time, memory, an end on stop.

Reading a description is arbitrary work on input nobody vetted: a parser, trimesh on a
2-million-triangle STL (over 150 s and 830 MB), CoACD. Run inside a world server it held the
interpreter lock and the world with it. `run` does it in a child forked from a fork server that
imported the converter once (a fresh interpreter spent ~1 s importing it; a fork takes
milliseconds), so the caller only waits on a pipe:
- the child limits its own address space to the memory budget; the caller kills it when it
  passes the time budget, and the error names the stage it was in (`stage`) and how to raise
  the budget;
- the child dies with the fork server, which ends with the caller (PR_SET_PDEATHSIG), and
  `stop_all` kills every child at once, so a stopping world never waits on one;
- the files the child read are announced in the caller with the audit event
  `converters.read`, so a cache that watches a conversion's reads sees them.
Results come back pickled: the child runs only the converter's own code (a served xacro runs in
a sandboxed grandchild that answers in JSON), so the bytes on the pipe are the converter's.
"""

from __future__ import annotations

import errno
import io
import multiprocessing
import os
import pickle
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from converters.budget import MEMORY_ENV, TIMEOUT_ENV, XacroBudget
from converters.errors import ConversionBudgetError, ConversionError, ConversionStoppedError

READ_EVENT = "converters.read"
# What the fork server imports once, so that a conversion's child starts warm.
PRELOAD = ["mujoco", "converters.warm"]
POLL_S = 0.1  # [s] how often a waiting caller looks at the stop flag
STAGE_BYTES = 512  # the stage text shared with the caller (a long path is cut)
SLACK_S = 2.0  # [s] a child outlives its time budget by at most this much, caller or not
_CODE_SUFFIXES = (".py", ".pyc", ".so", ".zip", ".pth")
_WRITE_MODES = ("w", "a", "x", "+")


@dataclass
class Running:
    """One child at work: what it converts, when it started (`time.monotonic`), its process,
    and the shared buffer it writes its stage to."""

    subject: str
    started: float
    process: Any
    board: Any

    @property
    def stage(self) -> str:
        """The stage the child said last (read without a lock: a torn read is only text)."""
        return self.board.value.decode(errors="replace") or "starting"


def run(work: Callable[[Any], Any], job: Any, budget: XacroBudget, subject: str) -> Any:
    """`work(job)` in a bounded child; its return value, or its error raised again here.

    Args:
        work: a module-level function (the child imports it by name).
        job: its picklable argument.
        budget: time [s] and address space [MiB] for the child.
        subject: the file being converted, for messages.

    Raises:
        ConversionBudgetError: over time or memory; names the stage and the variable to raise.
        ConversionStoppedError: `stop_all` was called meanwhile.
        ConversionError: any subclass the work raised, as the same class.
        RuntimeError: the work failed for another reason (a converter defect).
    """
    context = _context()
    receive, send = context.Pipe(duplex=False)
    board = context.RawArray("c", STAGE_BYTES)
    process = context.Process(
        target=_child,
        args=(send, board, work, job, (budget.timeout_s, budget.memory_mib), _place()),
        name="twin-conversion",
    )
    process.daemon = True
    running = Running(subject, time.monotonic(), process, board)
    with _LOCK:
        if _STOPPING.is_set():
            raise ConversionStoppedError(subject)
        process.start()
        _RUNNING.append(running)
    send.close()
    try:
        message = _wait(receive, running, budget)
    finally:
        with _LOCK:
            _RUNNING.remove(running)
        if process.is_alive():
            process.kill()
        process.join(5)
        receive.close()
    return _outcome(message, running, budget)


def stage(what: str, *, own_progress: bool = False) -> None:
    """Say what the conversion is doing now (a step and its file). In a bounded child it goes to
    the caller, which names it if the budget runs out and shows it as progress; elsewhere it goes
    to the `listening` callback, if any: None for a stage that shows its own progress
    (`own_progress`, collision meshes), so that the callback's display makes way."""
    global _stage
    _stage = what
    board, listener = _board, _listener
    if board is not None:  # a write to shared memory: no system call, cheap for every mesh
        board.value = what.encode(errors="replace")[: STAGE_BYTES - 1]
    if listener is not None:
        listener(None if own_progress else what)


@contextmanager
def listening(listener: Callable[[str | None], None]) -> Iterator[None]:
    """Call `listener` with each stage of a conversion in this process meanwhile (a CLI's
    progress display; the converter itself never writes to a stream)."""
    global _listener
    previous, _listener = _listener, listener
    try:
        yield
    finally:
        _listener = previous


def running() -> list[Running]:
    """The children at work now (for progress and `twin stats`-like views)."""
    with _LOCK:
        return list(_RUNNING)


def enable() -> None:
    """Bound this process's served conversions from now on (`enabled`), and start the fork
    server now (it imports the converter in the background, so the first conversion finds it
    warm). A world server calls it as it starts. Like any multiprocessing program, the process
    needs a main module its children may import again: a script guards its code with
    `if __name__ == "__main__":` (`python -m twin_cli` and the `twin` command do).
    """
    global _enabled
    _context()
    _enabled = True


def disable() -> None:
    """Convert in this process again (the fork server stays, idle, until the process ends)."""
    global _enabled
    _enabled = False


def enabled() -> bool:
    """Whether `enable` is in force in this process (a library user's World converts in the
    process, as before, with only xacro in a child)."""
    return _enabled


def stop_all() -> None:
    """Kill every child at work; from then on `run` fails at once (a process that is ending)."""
    with _LOCK:
        _STOPPING.set()
        for each in _RUNNING:
            each.process.kill()


_LOCK = threading.Lock()
_STOPPING = threading.Event()
_RUNNING: list[Running] = []
_started: Any = None
_enabled = False
_listener: Callable[[str | None], None] | None = None
_stage = "starting"  # in a child: the stage it is in
_board: Any = None  # in a child: the buffer shared with the caller


def _context() -> Any:
    """The fork-server context, its server started with the converter preloaded."""
    global _started
    if _started is None:
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(PRELOAD)
        from multiprocessing import forkserver

        forkserver.ensure_running()
        _started = context
    return _started


def _wait(receive: Any, running: Running, budget: XacroBudget) -> tuple:
    """The child's one message (its result, or its error), or ("died",)."""
    deadline = running.started + budget.timeout_s
    while True:
        if _STOPPING.is_set():
            raise ConversionStoppedError(running.subject)
        left = deadline - time.monotonic()
        if left <= 0:
            problem = f"took over {budget.timeout_s:g} s"
            raise ConversionBudgetError(running.subject, running.stage, problem, TIMEOUT_ENV)
        if not receive.poll(min(left, POLL_S)):
            continue
        try:
            return receive.recv()
        except (EOFError, OSError):
            return ("died",)


def _outcome(message: tuple, running: Running, budget: XacroBudget) -> Any:
    """The result in `message`, or the error it carries raised again."""
    kind = message[0]
    if kind in ("died", "memory") and _STOPPING.is_set():
        raise ConversionStoppedError(running.subject)
    code = running.process.exitcode
    if kind == "died" and running.stage == "starting" and (code or 0) > 0:
        raise RuntimeError(f"{running.subject}: the conversion worker failed to start ({code})")
    if kind in ("died", "memory"):
        problem = f"needed more than {budget.memory_mib} MiB"
        if kind == "died" and code is not None and code < 0:
            problem += f" (the worker ended with signal {-code})"
        raise ConversionBudgetError(running.subject, running.stage, problem, MEMORY_ENV)
    for name in message[2]:
        sys.audit(READ_EVENT, name)
    if kind == "done":
        return pickle.loads(message[1])
    if kind == "error":
        raise _rebuilt(message[1][0], message[1][1])
    raise RuntimeError(
        f"{running.subject}: the conversion failed while {running.stage}: {message[1]}"
    )


def _rebuilt(name: str, text: str) -> ConversionError:
    """The child's error as the same class (constructors take facts, so not `pickle`)."""
    from converters import errors

    cls = getattr(errors, name, None)
    if not (isinstance(cls, type) and issubclass(cls, ConversionError)):
        cls = ConversionError
    exc = cls.__new__(cls)
    Exception.__init__(exc, text)
    return exc


# ----------------------------------------------------------------------------- the child
def _child(
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
    global _board
    die_with_parent()
    _end_with_caller(send, timeout_s)
    os.environ.clear()
    os.environ.update(place[0])
    os.chdir(place[1])
    size = memory_mib * 1024 * 1024
    resource.setrlimit(resource.RLIMIT_AS, (size, size))
    _board = board
    files: set[str] = set()
    sys.addaudithook(_reads(files))
    try:
        message: tuple = ("done", _dumps(work(job)))
    except ConversionError as exc:
        message = ("error", (type(exc).__name__, str(exc)))
    except MemoryError:
        message = ("memory",)
    except RecursionError:  # a description nested past what a reader recurses through
        problem = f"{_stage}: nests deeper than twin can follow; flatten the description"
        message = ("error", ("ConversionError", problem))
    except Exception as exc:  # a converter defect, unless memory ran out in another guise
        message = ("memory",) if _out_of_memory(exc) else ("crash", f"{type(exc).__name__}: {exc}")
    send.send((*message, sorted(files)) if message[0] != "memory" else message)


def _place() -> tuple[dict, str]:
    """This process's environment and folder, for the child (the fork server's are older)."""
    return dict(os.environ), os.getcwd()


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


def _dumps(value: Any) -> bytes:
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
