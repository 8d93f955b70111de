"""Mesh files (STL, OBJ, DAE, PLY, GLB…) → scaled vertex/face arrays, with degeneracy checks."""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from converters.errors import MeshError
from converters.resources.mesh_data import MeshData

if TYPE_CHECKING:
    import trimesh
    from PIL.Image import Image

# Relative size below which a mesh counts as flat: smallest/largest principal extent.
FLAT_RATIO = 1e-6
# Smallest enclosed volume [m³] MuJoCo accepts for a mesh inertia (mjMINVAL-scale, padded).
MIN_VOLUME = 1e-12
# Binary STL: an 80-byte header and a uint32 triangle count, then per triangle a normal, three
# corners (little-endian float32) and a 2-byte attribute (the STL format; trimesh's `_stl_dtype`).
STL_HEADER_BYTES = 84
STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])


@dataclass
class MeshCache:
    """Meshes loaded during one conversion, keyed by (file, scale); files are read once."""

    loaded: dict[tuple[str, tuple[float, float, float]], MeshData] = field(default_factory=dict)

    def get(self, path: Path, scale: tuple[float, float, float], link: str) -> MeshData:
        key = (str(path), scale)
        if key not in self.loaded:
            raw = self.loaded.get((str(path), (1.0, 1.0, 1.0))) or load_mesh(path, link)
            vertices = raw.vertices * np.asarray(scale, dtype=float)
            faces = raw.faces if np.prod(scale) > 0 else raw.faces[:, ::-1]
            self.loaded[key] = MeshData(
                vertices, np.ascontiguousarray(faces), raw.rgba, raw.textured
            )
        return self.loaded[key]


def load_mesh(path: Path, link: str) -> MeshData:
    """A mesh file's triangles in metres: from the mesh store when these bytes were loaded
    before, else read with trimesh (and stored); from the read log when a bounded conversion's
    spec is built in its caller (`converters.isolated.replay`).

    Raises:
        MeshError: the file cannot be parsed or holds no triangles.
    """
    from converters.isolated.replay import read_once

    return read_once("mesh", (str(path),), lambda: _read_mesh(path, link))


def _read_mesh(path: Path, link: str) -> MeshData:
    from converters.isolated.stages import stage
    from converters.resources import mesh_store

    stage(f"reading mesh {path}{_size_of(path)}")
    try:
        key = mesh_store.key_of(path)
    except OSError as exc:
        raise MeshError(str(path), link, f"cannot be read ({exc})") from exc
    mesh = mesh_store.load(key)
    if mesh is None:
        mesh = read_mesh_file(path, link)
        mesh_store.store(key, mesh)
    if not np.all(np.isfinite(mesh.vertices)):
        raise MeshError(str(path), link, "holds vertices that are not numbers (NaN or infinity)")
    return mesh


def _size_of(path: Path) -> str:
    try:
        return f" ({path.stat().st_size / 1e6:.1f} MB)"
    except OSError:
        return ""


def read_mesh_file(path: Path, link: str) -> MeshData:
    """Read a mesh file: binary STL with numpy, every other format with trimesh.

    Raises:
        MeshError: the file cannot be parsed or holds no triangles.
    """
    mesh = read_binary_stl(path, link) if path.suffix.lower() == ".stl" else None
    return mesh if mesh is not None else read_with_trimesh(path, link)


def read_binary_stl(path: Path, link: str) -> MeshData | None:
    """A binary STL read with numpy, bit for bit as `read_with_trimesh` reads it (None when the
    file is not a binary STL, e.g. ASCII; trimesh then reads it).

    Importing trimesh (with scipy) costs 0.8-1 s, more than reading every mesh of a robot:
    turtlebot3 (binary STL visuals, primitive collisions) converts in 0.8-1.0 s with an empty
    cache instead of 1.8-2.3 s. Collision hulls not yet cached still use trimesh.
    trimesh's STL reader is the same record layout (`trimesh.exchange.stl.load_stl_binary`):
    a file whose length is not 84 + 50·count bytes is not binary. STL carries no unit: metres.

    Raises:
        MeshError: the file cannot be read or holds no triangles.
    """
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise MeshError(str(path), link, f"cannot be read ({exc})") from exc
    if len(data) < STL_HEADER_BYTES:
        return None
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=STL_HEADER_BYTES - 4)[0])
    if len(data) - STL_HEADER_BYTES != count * STL_RECORD.itemsize:
        return None
    if count == 0:
        raise MeshError(str(path), link, "holds no triangles")
    records = np.frombuffer(data, dtype=STL_RECORD, offset=STL_HEADER_BYTES)
    corners = records["vertices"].reshape(-1, 3).astype(np.float64)
    # The scene path's arithmetic with its identity node transform, so that signed zeros (and
    # so the bytes of the written STL) come out the same as through trimesh.
    identity = np.eye(4)
    corners = corners @ identity[:3, :3].T + identity[:3, 3]
    faces = np.arange(3 * count, dtype=np.int64).reshape(-1, 3)
    vertices, faces = _merge_duplicates(corners, faces)
    return MeshData(vertices, faces)


def read_with_trimesh(path: Path, link: str) -> MeshData:
    """Read any mesh format trimesh knows, flattening scenes (DAE/GLB) with their transforms.

    COLLADA unit declarations are applied. Textures and materials are not copied (copying
    images dominated DAE load time: 1.7 s → 0.3 s for ANYmal's 19 textured DAE files).

    Raises:
        MeshError: the file cannot be parsed or holds no triangles.
    """
    import trimesh

    logging.getLogger("trimesh").setLevel(logging.ERROR)
    try:
        loaded = trimesh.load_scene(str(path), process=False)
    except Exception as exc:  # trimesh raises many types for corrupt files
        raise MeshError(str(path), link, f"cannot be read ({exc})") from exc
    parts_v: list[np.ndarray] = []
    parts_f: list[np.ndarray] = []
    count = 0
    for node in loaded.graph.nodes_geometry:
        transform, name = loaded.graph[node]
        geometry = loaded.geometry.get(name)
        if geometry is None or not hasattr(geometry, "faces") or len(geometry.faces) == 0:
            continue
        vertices = np.asarray(geometry.vertices, dtype=float)
        parts_v.append(vertices @ transform[:3, :3].T + transform[:3, 3])
        parts_f.append(np.asarray(geometry.faces, dtype=np.int64) + count)
        count += len(vertices)
    if not parts_v:
        raise MeshError(str(path), link, "holds no triangles")
    vertices, faces = _merge_duplicates(np.concatenate(parts_v), np.concatenate(parts_f))
    rgba, textured = _main_colour(loaded)
    return MeshData(vertices * _unit_to_metres(loaded, path), faces, rgba, textured)


def _main_colour(scene: trimesh.Scene) -> tuple[tuple[float, float, float, float] | None, bool]:
    """The colour of the geometry with most faces that defines one, and whether any is textured.

    Gazebo draws a mesh in its own material colours when the URDF gives none; MuJoCo geoms
    have one rgba, so the dominant colour stands in for the file's materials.
    """
    best: tuple[int, tuple[float, float, float, float]] | None = None
    textured = False
    for geometry in scene.geometry.values():
        visual = getattr(geometry, "visual", None)
        material = getattr(visual, "material", None)
        image = getattr(material, "image", None) or getattr(material, "baseColorTexture", None)
        textured = textured or image is not None
        try:
            if image is not None:
                colour = _mean_colour(image)
            elif material is not None:
                colour = material.main_color
            elif visual is not None and getattr(visual, "defined", False):
                colour = visual.main_color
            else:
                continue
        except (AttributeError, ValueError, IndexError):
            continue
        rgba = tuple(float(c) / 255.0 for c in np.asarray(colour).reshape(-1)[:4])
        faces = len(getattr(geometry, "faces", ()))
        if len(rgba) == 4 and (best is None or faces > best[0]):
            best = (faces, rgba)
    return (best[1] if best else None), textured


def _mean_colour(image: Image) -> np.ndarray:
    """Average RGBA [0-255] of a texture image, from about 16×16 strided pixels.

    Strided sampling of the decoded pixels avoids converting and resizing whole textures
    (ANYmal's 19 DAE files: 1.25 s → a few ms).
    """
    if getattr(image, "_im", True) is None and hasattr(image, "draft"):
        image.draft("RGB", (64, 64))  # JPEG: decode at 1/8 scale when not decoded yet
    pixels = np.asarray(image)
    step = max(1, max(pixels.shape[:2]) // 16)
    sample = pixels[::step, ::step].astype(float)
    if sample.ndim == 2:  # greyscale
        sample = np.repeat(sample[..., None], 3, axis=2)
    rgb = sample[..., :3].reshape(-1, 3).mean(axis=0)
    return np.append(rgb, 255.0)


def _unit_to_metres(scene: trimesh.Scene, path: Path) -> float:
    """COLLADA files declare their unit (`<unit meter="0.0254"/>`); Gazebo's loader applies it,
    so we do too (aliengo's calf.dae is in inches). Other formats carry no unit: metres."""
    from trimesh.units import unit_conversion

    units = getattr(scene, "units", None)
    if path.suffix.lower() != ".dae" or not units:
        return 1.0
    try:
        return float(unit_conversion(units, "meters"))
    except (ValueError, KeyError):
        return 1.0


def _merge_duplicates(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge bit-identical vertices (STL stores three per triangle); drop collapsed triangles.

    Sorting the three columns with `lexsort` is 4x faster than `np.unique(axis=0)` (8 ms vs
    37 ms for a 58k-vertex STL); the result is the same sorted unique set.
    """
    if len(vertices) == 0:
        return vertices, faces.astype(np.int32)
    order = np.lexsort((vertices[:, 2], vertices[:, 1], vertices[:, 0]))
    ordered = vertices[order]
    first = np.empty(len(ordered), dtype=bool)
    first[0] = True
    first[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    inverse = np.empty(len(ordered), dtype=np.int64)
    inverse[order] = np.cumsum(first) - 1
    faces = inverse[faces]
    keep = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    return ordered[first], np.ascontiguousarray(faces[keep], dtype=np.int32)


def mesh_problem(mesh: MeshData) -> str | None:
    """Why MuJoCo could not use this mesh for collision (None when it is fine).

    Degenerate meshes: fewer than 4 vertices, all vertices in a plane or on a line (flat), or
    a convex hull of (almost) zero volume.
    """
    if len(mesh.vertices) < 4 or len(mesh.faces) < 1:
        return f"{len(mesh.vertices)} vertices, {len(mesh.faces)} faces (need ≥ 4 vertices)"
    centred = mesh.vertices - mesh.vertices.mean(axis=0)
    extents = np.linalg.svd(centred[:: max(1, len(centred) // 5000)], compute_uv=False)
    if extents[0] <= 0 or extents[-1] / extents[0] < FLAT_RATIO:
        return "flat (all vertices in one plane or on a line)"
    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    if float(np.prod(hi - lo)) < MIN_VOLUME:
        return f"zero volume (bounding box {np.round(hi - lo, 9).tolist()} m)"
    return None
