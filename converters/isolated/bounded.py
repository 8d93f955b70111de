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

import multiprocessing
import os
import pickle
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from converters.errors import (
    ConversionBudgetError,
    ConversionStoppedError,
    rebuilt_error,
)
from converters.isolated import bounded_child, stages
from converters.isolated.bounded_child import READ_EVENT
from converters.isolated.budget import MEMORY_ENV, TIMEOUT_ENV, XacroBudget

# What the fork server imports once, so that a conversion's child starts warm.
PRELOAD = ["mujoco", "converters.serving.warm"]
POLL_S = 0.1  # [s] how often a waiting caller looks at the stop flag


@dataclass
class Running:
    """One child at work: what it converts, when it started (`time.monotonic`), its process,
    the shared buffer it writes its stage to, and the event that cancels it (or None)."""

    subject: str
    started: float
    process: Any
    board: Any
    cancel: threading.Event | None = None

    @property
    def stage(self) -> str:
        """The stage the child said last (`converters.isolated.stages`)."""
        return stages.read(self.board)


def run(
    work: Callable[[Any], Any],
    job: Any,
    budget: XacroBudget,
    subject: str,
    cancel: threading.Event | None = None,
) -> Any:
    """`work(job)` in a bounded child; its return value, or its error raised again here.

    Args:
        work: a module-level function (the child imports it by name).
        job: its picklable argument.
        budget: time [s] and address space [MiB] for the child.
        subject: the file being converted, for messages.
        cancel: once set, the child is killed and the call ends (a background conversion
            nobody waits for any more).

    Raises:
        ConversionBudgetError: over time or memory; names the stage and the variable to raise.
        ConversionStoppedError: `stop_all` was called meanwhile, or `cancel` was set.
        ConversionError: any subclass the work raised, as the same class.
        RuntimeError: the work failed for another reason (a converter defect).
    """
    context = _context()
    receive, send = context.Pipe(duplex=False)
    board = context.RawArray("c", stages.STAGE_BYTES)
    process = context.Process(
        target=bounded_child.serve,
        args=(
            send,
            board,
            work,
            job,
            (budget.timeout_s, budget.memory_mib),
            (dict(os.environ), os.getcwd()),
        ),
        name="twin-conversion",
    )
    process.daemon = True
    running = Running(subject, time.monotonic(), process, board, cancel)
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
        if _STOPPING.is_set() or (running.cancel is not None and running.cancel.is_set()):
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
    if kind == "died" and running.stage == stages.STARTING and (code or 0) > 0:
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
        raise rebuilt_error(message[1][0], message[1][1])
    raise RuntimeError(
        f"{running.subject}: the conversion failed while {running.stage}: {message[1]}"
    )
