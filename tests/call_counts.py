"""How often named converter functions run during an action, seen with `sys.setprofile`: what a
child process or a build does, watched in the test's own process."""

from __future__ import annotations

import sys
from collections.abc import Callable


def converter_calls(action: Callable[[], object], names: set[str]) -> dict[str, int]:
    """How often each function of `names` (converter functions, by name) ran during `action`."""
    counts = dict.fromkeys(names, 0)

    def profile(frame, event, arg) -> None:  # noqa: ARG001 (sys.setprofile's signature)
        code = frame.f_code
        if event == "call" and code.co_name in counts and "converters" in code.co_filename:
            counts[code.co_name] += 1

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return counts
