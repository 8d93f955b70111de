"""Supervisor of a background world server: runs it, reaps it, records how and when it ended.

`python -m twin_cli.server.supervisor EXIT_RECORD -- COMMAND...` starts COMMAND (the server),
waits for it and writes EXIT_RECORD (`<world>.exit.json`: pid, returncode, end time) however it
ended, a SIGKILL included, then exits with the server's code. The server cannot record its own
SIGKILL; its parent sees it in the wait status (`waitpid(2)`). Standard library only: it stays
a small process (~10 MB resident) for the server's whole life.
SIGTERM and SIGINT sent to the supervisor are passed on to the server.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from twin_cli.server.lifecycle import write_json


def supervise(record: Path, command: list[str]) -> int:
    """Run `command` to its end and write `record`; returns the exit code to pass on."""
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # no terminal, but be sure
    proc = subprocess.Popen(command)
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda signum, frame: proc.send_signal(signum))
    while True:
        try:
            returncode = proc.wait()
            break
        except InterruptedError:  # pragma: no cover (PEP 475 retries; kept for clarity)
            continue
    write_json(record, {"pid": proc.pid, "returncode": returncode, "ended": time.time()})
    return returncode if returncode >= 0 else 128 - returncode


def main(argv: list[str]) -> int:
    """`EXIT_RECORD -- COMMAND...`."""
    if len(argv) < 3 or argv[1] != "--":
        sys.stderr.write("usage: python -m twin_cli.server.supervisor EXIT_RECORD -- COMMAND...\n")
        return 2
    return supervise(Path(argv[0]), argv[2:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
