"""The conversion report: what was mapped, approximated, ignored or repaired, and why."""

from __future__ import annotations

import enum
from dataclasses import asdict, dataclass, field
from typing import Any


class Outcome(enum.Enum):
    """How one source element or tag was handled."""

    MAPPED = "mapped"
    APPROXIMATED = "approximated"
    IGNORED = "ignored"
    REPAIRED = "repaired"
    WARNING = "warning"


@dataclass(frozen=True)
class Entry:
    """One finding: `subject` is the link/joint/file/tag it concerns (e.g. "link 'wheel' mu2")."""

    outcome: Outcome
    subject: str
    detail: str
    tag: str | None = None


@dataclass
class Report:
    """Everything the converter did that a user should know, plus summary figures."""

    robot: str = ""
    source: str = ""
    entries: list[Entry] = field(default_factory=list)
    summary: dict[str, Any] = field(default_factory=dict)
    meshes: list[dict[str, Any]] = field(default_factory=list)

    def add(self, outcome: Outcome, subject: str, detail: str, tag: str | None = None) -> None:
        self.entries.append(Entry(outcome, subject, detail, tag))

    def mapped(self, subject: str, detail: str, tag: str | None = None) -> None:
        self.add(Outcome.MAPPED, subject, detail, tag)

    def approximated(self, subject: str, detail: str, tag: str | None = None) -> None:
        self.add(Outcome.APPROXIMATED, subject, detail, tag)

    def ignored(self, subject: str, detail: str, tag: str | None = None) -> None:
        self.add(Outcome.IGNORED, subject, detail, tag)

    def repaired(self, subject: str, detail: str, tag: str | None = None) -> None:
        self.add(Outcome.REPAIRED, subject, detail, tag)

    def warn(self, subject: str, detail: str, tag: str | None = None) -> None:
        self.add(Outcome.WARNING, subject, detail, tag)

    def of(self, outcome: Outcome) -> list[Entry]:
        return [e for e in self.entries if e.outcome is outcome]

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready view (enums as their values)."""
        out = asdict(self)
        out["entries"] = [{**asdict(e), "outcome": e.outcome.value} for e in self.entries]
        return out
