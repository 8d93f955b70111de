"""Run every benchmark module (`benchmarks/bench_*.py`, each with `run() -> dict`) and print JSON.

Targets are ratios measured within one run (twin vs raw mj_step, cached vs cold), so they hold
on any machine; absolute figures are printed for the record.
"""

from __future__ import annotations

import importlib
import json
import pkgutil
import sys
import time

import benchmarks


def main(selected: list[str]) -> int:
    results: dict[str, object] = {}
    for info in sorted(pkgutil.iter_modules(benchmarks.__path__), key=lambda m: m.name):
        if not info.name.startswith("bench_"):
            continue
        if selected and info.name.removeprefix("bench_") not in selected:
            continue
        module = importlib.import_module(f"benchmarks.{info.name}")
        start = time.perf_counter()
        print(f"# {info.name} ...", file=sys.stderr, flush=True)
        results[info.name] = module.run()
        print(f"# {info.name}: {time.perf_counter() - start:.1f} s", file=sys.stderr, flush=True)
        print(json.dumps({info.name: results[info.name]}, indent=2, default=str), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
