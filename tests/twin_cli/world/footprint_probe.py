"""The modules of twin one cold `World.spawn` executes code in, counted in a fresh interpreter.

Run by `test_spawn_footprint` as `python footprint_probe.py FILE`; prints JSON. A fresh process
makes every count the same alone or in a suite: no conversion is cached yet, and no module an
earlier test imported hides the class bodies its import runs. `sys.setprofile` sees every Python
call; a module counts when a function, method, comprehension or class body of it runs, its module
body alone (an import) does not.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
OURS = ("twin_cli/", "converters/")


def modules_run(action: Callable[[], object]) -> set[str]:
    """Paths (from the repository root) of twin's modules that executed code during `action`."""
    root = f"{ROOT}/"
    seen: set[str] = set()

    def profile(frame, event, arg) -> None:  # noqa: ARG001 (sys.setprofile's signature)
        code = frame.f_code
        if event == "call" and code.co_name != "<module>":
            seen.add(code.co_filename)

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return {f[len(root) :] for f in seen if f.startswith(root) and f[len(root) :].startswith(OURS)}


def main(source: str) -> dict:
    """One spawn of `source` into a new world: the modules it ran, the conversion cache's hits
    and misses meanwhile, and the world's entities after."""
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World
    from twin_cli.world.conversion_cache import CACHE

    world = World()
    hits, misses = CACHE.hits, CACHE.misses
    ran = modules_run(lambda: world.spawn(SpawnRequest(source=source), name="robot"))
    return {
        "modules": sorted(ran),
        "hits": CACHE.hits - hits,
        "misses": CACHE.misses - misses,
        "entities": list(world.entity_names()),
    }


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1])))
