"""A model bundle cut into pieces keyed by the hash of their bytes, so a page that holds a
piece never downloads it again.

MuJoCo's page downloads the whole bundle (an MJB plus textures) on every model change: after a
spawn, the meshes of every robot again (16 MiB for two turtlebot3, most of it mesh data and mesh
BVHs). Here each mesh's rows of the mesh arrays, each texture's bytes and each body's and mesh's
BVH are pieces of their own (an item is the same bytes wherever the items added before it
pushed it), and the bytes between them (the structure: bodies, joints, names) are cut where
their content says (a hash of the 32 bytes before a position picks it, so an unchanged run cuts
the same wherever it moved). A spawn that adds no new mesh leaves every mesh piece unchanged,
and the page fetches only the structure that changed. The cuts only decide what can be reused;
the pieces always put back the bundle byte for byte.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np

MIN_PIECE = 16 * 1024  # [bytes] no content cut closer than this to the previous one
MAX_PIECE = 1024 * 1024  # [bytes] a cut at least this often, whatever the content
CUT_BITS = 16  # a content cut where the top 16 bits of the hash are 0: ~64 KiB pieces
HASH_MULTIPLIER = 0x9E3779B97F4A7C15  # odd 64-bit (golden ratio): mixes the window's bytes
HASH_OFFSET = 0x5BD1E9955BD1E995  # keeps a run of zero bytes from cutting everywhere
WINDOW = 32  # [bytes] the content a cut depends on (8 small ints repeat too often)
# Model arrays that hold meshes, textures and their BVHs: the bytes worth keeping on the page.
ASSET_PREFIXES = ("mesh_", "tex_data", "hfield_data", "skin_")
ASSET_MIN_BYTES = 1024  # [bytes] smaller arrays are left to the content cuts
KEY_BYTES = 16  # blake2b digest size: 128 bits, no accidental collision


@dataclass(frozen=True)
class Piece:
    """`size` bytes of the bundle from `start`, named by `key` (hex blake2b of the bytes);
    `asset`: inside a mesh or texture array."""

    key: str
    start: int
    size: int
    asset: bool


@dataclass(frozen=True)
class Manifest:
    """A bundle (identified by MuJoCo's crc32 of it) as the pieces that make it, in order."""

    crc32: int
    size: int
    pieces: tuple[Piece, ...]

    def as_json(self) -> dict[str, Any]:
        """What the page reads: `pieces` as [key, size, asset] rows."""
        rows = [[p.key, p.size, int(p.asset)] for p in self.pieces]
        return {"crc32": self.crc32, "size": self.size, "pieces": rows}

    @property
    def asset_bytes(self) -> int:
        return sum(p.size for p in self.pieces if p.asset)


def array_ranges(bundle: bytes, model: Any) -> list[tuple[int, int, bool]]:
    """[start, end) in `bundle` of each mesh's and texture's slice of the model's mesh, texture
    and BVH arrays, sorted and disjoint, each with whether it holds mesh or texture data. An
    array is found by its bytes (MJB's layout is MuJoCo's own); one found nowhere, or a slice
    overlapping another, is left to the content cuts, which costs reuse, never correctness."""
    found: list[tuple[int, int, bool]] = []
    cursor = 0  # the arrays are searched in MJB's order, each from where the last one ended
    for name, items in (_items(model) if model is not None else {}).items():
        array = getattr(model, name, None)
        if not isinstance(array, np.ndarray) or array.nbytes < ASSET_MIN_BYTES:
            continue
        data = array.tobytes()
        start = cursor if bundle.startswith(data, cursor) else bundle.find(data, cursor)
        start = start if start >= 0 else bundle.find(data)  # another order: the whole bundle
        if start < 0:
            continue
        cursor = start + array.nbytes
        row = array.nbytes // max(1, len(array))
        asset = name.startswith(ASSET_PREFIXES)
        found += [(start + a * row, start + (a + n) * row, asset) for a, n in items if n > 0]
    ranges: list[tuple[int, int, bool]] = []
    for start, end, asset in sorted(found):
        if not ranges or start >= ranges[-1][1]:
            ranges.append((start, end, asset))
    return ranges


# Per-item arrays and the (address, count) fields that say where each mesh's rows are, in the
# order MJB stores them (a face array equal to the one before is then found where it is).
MESH_ROWS = {
    "mesh_vert": ("mesh_vertadr", "mesh_vertnum"),
    "mesh_normal": ("mesh_normaladr", "mesh_normalnum"),
    "mesh_texcoord": ("mesh_texcoordadr", "mesh_texcoordnum"),
    "mesh_face": ("mesh_faceadr", "mesh_facenum"),
    "mesh_facenormal": ("mesh_faceadr", "mesh_facenum"),
    "mesh_facetexcoord": ("mesh_faceadr", "mesh_facenum"),
    "mesh_polymapadr": ("mesh_vertadr", "mesh_vertnum"),
    "mesh_polymapnum": ("mesh_vertadr", "mesh_vertnum"),
}
BVH_ARRAYS = ("bvh_depth", "bvh_child", "bvh_nodeid", "bvh_aabb")


def _items(model: Any) -> dict[str, list[tuple[int, int]]]:
    """(first row, rows) of each mesh, texture, and body's and mesh's BVH, per array, in the
    order MJB stores the arrays: an item is the same bytes wherever the items added before it
    pushed it."""
    trees = _rows(model.body_bvhadr, model.body_bvhnum) + _rows(
        model.mesh_bvhadr, model.mesh_bvhnum
    )
    items = {name: trees for name in BVH_ARRAYS}
    items.update(
        {
            name: _rows(getattr(model, adr), getattr(model, num))
            for name, (adr, num) in MESH_ROWS.items()
        }
    )
    sizes = model.tex_height * model.tex_width * model.tex_nchannel
    items["tex_data"] = _rows(model.tex_adr, sizes)
    return items


def _rows(adr: Any, num: Any) -> list[tuple[int, int]]:
    return [(int(a), int(n)) for a, n in zip(adr, num, strict=True) if a >= 0]


def content_cuts(bundle: bytes, lo: int, hi: int) -> list[int]:
    """Cut points in (lo, hi], the last one `hi`: where the hash of the `WINDOW` bytes before a
    position has its top `CUT_BITS` bits zero, at least `MIN_PIECE` and at most `MAX_PIECE`
    apart. Vectorised: one numpy pass, no Python per byte."""
    if hi - lo <= MIN_PIECE + WINDOW:
        return [hi]
    count = hi - lo - WINDOW + 1
    mixed = np.full(count, HASH_OFFSET, dtype=np.uint64)
    with np.errstate(over="ignore"):
        for word in range(0, WINDOW, 8):  # each 8 bytes of the window, folded in turn
            part = np.ndarray((count,), dtype="<u8", buffer=bundle, offset=lo + word, strides=(1,))
            mixed = (mixed ^ part) * np.uint64(HASH_MULTIPLIER)
    candidates = np.flatnonzero((mixed >> np.uint64(64 - CUT_BITS)) == 0) + (lo + WINDOW)
    cuts, pos = [], lo
    while pos < hi:
        i = int(np.searchsorted(candidates, pos + MIN_PIECE))
        nxt = int(candidates[i]) if i < len(candidates) else hi
        nxt = min(nxt, pos + MAX_PIECE, hi)
        cuts.append(nxt)
        pos = nxt
    return cuts


def split_bundle(bundle: bytes, crc32: int, ranges: list[tuple[int, int, bool]]) -> Manifest:
    """The bundle as pieces: each of `ranges` (`array_ranges`) whole (cut every `MAX_PIECE`
    from its start), the bytes between them cut by content."""
    bounds = sorted({0, len(bundle), *(b for r in ranges for b in r[:2])})
    view = memoryview(bundle)
    pieces: list[Piece] = []
    ends = iter(ranges)
    current = next(ends, None)
    for lo, hi in zip(bounds, bounds[1:], strict=False):
        while current is not None and current[1] <= lo:
            current = next(ends, None)
        inside = current is not None and current[0] <= lo and hi <= current[1]
        asset = inside and current is not None and current[2]
        # An item's slice is cut at fixed steps from its start; the bytes between by content.
        if inside:
            cuts = [*range(lo + MAX_PIECE, hi, MAX_PIECE), hi]
        else:
            cuts = content_cuts(bundle, lo, hi)
        start = lo
        for cut in cuts:
            key = hashlib.blake2b(view[start:cut], digest_size=KEY_BYTES).hexdigest()
            pieces.append(Piece(key, start, cut - start, asset))
            start = cut
    return Manifest(crc32, len(bundle), tuple(pieces))
