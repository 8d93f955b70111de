"""World files an older twin wrote, kept under tests/twin_cli/world/saves/ with their robots."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

SAVES = Path(__file__).parent / "twin_cli" / "world" / "saves"


def placed_save(name: str, parts: tuple[str, ...], folder: Path) -> Path:
    """Save `name` copied into `folder` with its robots' files (`<name>_<part>`, one per
    entity, in order; a part without a suffix is a `.urdf`), each entity's source naming its
    copy."""
    doc = json.loads((SAVES / f"{name}.json").read_text())
    for entity, part in zip(doc["entities"], parts, strict=True):
        file = part if "." in part else f"{part}.urdf"
        entity["source"] = str(shutil.copy(SAVES / f"{name}_{file}", folder / file))
    path = folder / "world.json"
    path.write_text(json.dumps(doc))
    return path
