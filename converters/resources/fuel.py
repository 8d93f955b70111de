"""Gazebo Fuel's local cache: where `gz fuel download` and gz-sim keep the models they fetched.

A Fuel model lives at `HOST/owner/models/name/VERSION/` under the cache (owner and name lower
case, VERSION a number); a file of it is named on the web as
`https://HOST/1.0/OWNER/models/NAME/VERSION/files/REL` (VERSION may be `tip`, the newest).
twin reads the cache and never downloads.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from urllib.parse import unquote


def fuel_caches(env: Mapping[str, str]) -> list[Path]:
    """GZ_FUEL_CACHE_PATH, else ~/.gz/fuel and Ignition's ~/.ignition/fuel."""
    if env.get("GZ_FUEL_CACHE_PATH"):
        return [Path(env["GZ_FUEL_CACHE_PATH"]).expanduser()]
    home = Path.home()
    return [home / ".gz" / "fuel", home / ".ignition" / "fuel"]


def is_web_uri(uri: str) -> bool:
    return uri.startswith(("http://", "https://"))


def fuel_file(uri: str, env: Mapping[str, str]) -> Path | None:
    """The cached copy of a Fuel model's file (`.../models/NAME/VERSION/files/REL`), or None when
    the URI names no model file or the cache lacks it."""
    parts = [unquote(p) for p in uri.split("://", 1)[1].split("/") if p]
    if "models" not in parts[1:] or "files" not in parts:
        return None
    at, files = parts.index("models"), parts.index("files")
    if not 0 < at < files - 1:
        return None
    host, owner, name, rest = parts[0], parts[at - 1], parts[at + 1], parts[files + 1 :]
    if any(p in (".", "..") or "/" in p or "\\" in p for p in (host, owner, name, *rest)):
        return None  # a web address names nothing outside its model's folder
    version = parts[at + 2] if files > at + 2 else "tip"
    for cache in fuel_caches(env):
        model = cache / host / owner.lower() / "models" / name.lower()
        numbered = sorted(
            (d for d in model.glob("*") if d.is_dir() and d.name.isdigit()),
            key=lambda d: int(d.name),
        )
        chosen = numbered[-1:] if version == "tip" else [d for d in numbered if d.name == version]
        for directory in chosen:
            candidate = directory.joinpath(*rest)
            if candidate.is_file():
                return candidate
    return None
