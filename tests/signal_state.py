"""What a process that did not end on a signal was doing: the evidence a timed-out Ctrl-C test
reports, so that a failure names its cause (a signal ignored or blocked, a process stopped
in the kernel) instead of only the timeout."""

from __future__ import annotations

from pathlib import Path

SIGINT_BIT = 1 << 1  # bit (signal number − 1) of /proc's signal masks


def signal_state(pid: int) -> str:
    """One line: the process's state, whether SIGINT is ignored, blocked, caught or pending,
    and where it waits in the kernel ("gone" once it has ended)."""
    try:
        status = dict(
            line.split(":\t", 1)
            for line in Path(f"/proc/{pid}/status").read_text().splitlines()
            if ":\t" in line
        )
        wchan = Path(f"/proc/{pid}/wchan").read_text().strip() or "-"
    except OSError:
        return f"pid {pid}: gone"
    sigint = {
        name: bool(int(status.get(key, "0"), 16) & SIGINT_BIT)
        for name, key in (("ignored", "SigIgn"), ("blocked", "SigBlk"), ("caught", "SigCgt"))
    }
    pending = bool(int(status.get("ShdPnd", "0"), 16) & SIGINT_BIT) or bool(
        int(status.get("SigPnd", "0"), 16) & SIGINT_BIT
    )
    marks = ", ".join(f"SIGINT {k}" for k, v in sigint.items() if v) or "SIGINT default"
    return (
        f"pid {pid}: state {status.get('State', '?').strip()}, {marks}"
        f"{', SIGINT pending' if pending else ''}, waits in {wchan}"
    )
