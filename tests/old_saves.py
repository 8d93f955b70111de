"""World files an older twin wrote, kept under tests/twin_cli/world/saves/ with their robots."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

SAVES = Path(__file__).parent / "twin_cli" / "world" / "saves"


def placed_save(name: str, parts: tuple[str, ...], folder: Path) -> Path:
    """Save `name` copied into `folder` with its robots' URDFs (`<name>_<part>.urdf`, one per
    entity, in order), each entity's source naming its copy."""
    doc = json.loads((SAVES / f"{name}.json").read_text())
    for entity, part in zip(doc["entities"], parts, strict=True):
        entity["source"] = str(shutil.copy(SAVES / f"{name}_{part}.urdf", folder / f"{part}.urdf"))
    path = folder / "world.json"
    path.write_text(json.dumps(doc))
    return path
