"""How much time and memory a served conversion and its xacro expansion may take (settable)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

TIMEOUT_ENV, MEMORY_ENV = "TWIN_CONVERT_TIMEOUT", "TWIN_CONVERT_MEMORY"
DEFAULT_TIMEOUT_S = 120.0  # [s] the largest corpus xacro expands in under 2 s
DEFAULT_MEMORY_MIB = 4096  # [MiB] address space (mostly the interpreter's own mappings)


@dataclass(frozen=True)
class XacroBudget:
    """How long [s] and how much address space [MiB] one served conversion
    (`converters.isolated.bounded`) and, within it, its xacro expansion may take."""

    timeout_s: float = DEFAULT_TIMEOUT_S
    memory_mib: int = DEFAULT_MEMORY_MIB

    @classmethod
    def from_env(cls, env: dict[str, str] | None = None) -> XacroBudget:
        """The budget from `TWIN_CONVERT_TIMEOUT` [s] and `TWIN_CONVERT_MEMORY` [MiB]."""
        env = dict(os.environ if env is None else env)
        return cls(
            _positive(env.get(TIMEOUT_ENV), DEFAULT_TIMEOUT_S),
            int(_positive(env.get(MEMORY_ENV), DEFAULT_MEMORY_MIB)),
        )


def _positive(text: str | None, default: float) -> float:
    try:
        value = float(text) if text else default
    except ValueError:
        return default
    return value if math.isfinite(value) and value > 0 else default
