"""Gazebo Fuel's local cache: where `gz fuel download` and gz-sim keep the models they fetched.

A Fuel model lives at `HOST/owner/models/name/VERSION/` under the cache (owner and name lower
case, VERSION a number); a file of it is named on the web as
`https://HOST/1.0/OWNER/models/NAME/VERSION/files/REL` (VERSION may be `tip`, the newest).
twin reads the cache and never downloads.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
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


@dataclass(frozen=True)
class FuelAddress:
    """A Fuel model's web address, split: `https://HOST/1.0/OWNER/models/NAME[/VERSION]` and,
    for one of its files, `/files/REL` (`rest`). VERSION None: the newest."""

    host: str
    owner: str
    name: str
    version: str | None
    rest: tuple[str, ...] = ()


def parse_address(uri: str) -> FuelAddress | None:
    """`uri` as a Fuel model's (or file's) address, or None when it names none: no `models`
    segment, or a segment that would lead out of the model's folder (`.`, `..`, a slash once
    decoded)."""
    parts = [unquote(p) for p in uri.split("://", 1)[1].split("/") if p]
    if any(p in (".", "..") or "/" in p or "\\" in p for p in parts):
        return None  # a web address names nothing outside its model's folder
    if "models" not in parts[1:-1]:
        return None
    at = parts.index("models")
    files = parts.index("files") if "files" in parts[at:] else len(parts)
    version = parts[at + 2] if files > at + 2 else None
    rest = tuple(parts[files + 1 :])
    return FuelAddress(parts[0], parts[at - 1], parts[at + 1], version, rest)


def cached_model(address: FuelAddress, env: Mapping[str, str]) -> Path | None:
    """The cache folder of the address's model version (the newest for None or `tip`), or None
    when no cache holds it."""
    wanted = None if address.version in (None, "tip") else address.version
    for cache in fuel_caches(env):
        model = cache / address.host / address.owner.lower() / "models" / address.name.lower()
        numbered = sorted(
            (d for d in model.glob("*") if d.is_dir() and d.name.isdigit()),
            key=lambda d: int(d.name),
        )
        chosen = [d for d in numbered if wanted is None or d.name == wanted]
        if chosen:
            return chosen[-1]
    return None


def fuel_file(uri: str, env: Mapping[str, str]) -> Path | None:
    """The cached copy of a Fuel model's file (`.../models/NAME/VERSION/files/REL`), or None when
    the URI names no model file or the cache lacks it."""
    address = parse_address(uri)
    model = cached_model(address, env) if address is not None and address.rest else None
    found = model.joinpath(*address.rest) if model is not None and address is not None else None
    return found if found is not None and found.is_file() else None
