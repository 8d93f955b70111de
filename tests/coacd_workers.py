"""The CoACD worker processes under a process, read from /proc: how many decompositions run."""

from __future__ import annotations

from pathlib import Path

WORKER = "converters.collision.worker"  # a CoACD worker process's command line


def descendants(pid: int) -> dict[int, str]:
    """Every process under `pid`: pid → command line."""
    parents: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    found, frontier = {}, [pid]
    while frontier:
        parent = frontier.pop()
        for child, of in parents.items():
            if of == parent and child not in found:
                try:
                    found[child] = (Path("/proc") / str(child) / "cmdline").read_text()
                except OSError:
                    continue
                frontier.append(child)
    return found


def workers(pid: int) -> list[int]:
    """The live CoACD workers under `pid`."""
    return [
        p for p, line in descendants(pid).items() if WORKER in line.replace("\0", " ") and alive(p)
    ]


def alive(pid: int) -> bool:
    """Whether process `pid` runs (a zombie, dead but not yet reaped, does not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"
