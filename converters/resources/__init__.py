"""Files a description refers to: packages and URIs (`package://`, `model://`, ...) and meshes."""

from __future__ import annotations

from converters.resources.mesh_data import MeshData
from converters.resources.meshes import MeshCache, load_mesh, mesh_problem
from converters.resources.packages import PackageResolver

__all__ = ["MeshCache", "MeshData", "PackageResolver", "load_mesh", "mesh_problem"]
