"""Rigid-body inertia: link inertials in body frames, merging (lumping), validation, repair."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from converters.description import Inertial

# Tolerance of the checks, relative to the largest principal moment: MuJoCo itself rejects a
# triangle-inequality violation only beyond its mjMINVAL (1e-15), so this is stricter than needed.
REL_TOL = 1e-9
# [kg], [kg m²], [m]: no robot part comes near it (a 1000 t ship hull is ~1e9 kg m²); past it a
# value is a typo or an attack, and its squares overflow a double when the frame turns.
MAX_MAGNITUDE = 1e15
# Smallest principal moment a repaired tensor keeps, relative to its largest (and absolute [kg·m²]).
REPAIR_MIN_REL = 1e-3
REPAIR_MIN_ABS = 1e-9
# Off-diagonal terms below this fraction of the largest moment count as zero (rounding only).
DIAGONAL_TOL = 1e-14
# Density [kg/m³] used to give a massless moving link a mass from its geometry's bounding box.
REPAIR_DENSITY = 1000.0
# Mass [kg] and half size [m] for a repaired link that has no geometry at all.
REPAIR_FALLBACK_MASS = 0.01
REPAIR_FALLBACK_HALF = 0.01


@dataclass(frozen=True)
class Inertia:
    """Mass [kg], centre of mass (3,) [m] and tensor about the COM (3, 3) [kg·m²], one frame."""

    mass: float
    com: np.ndarray
    tensor: np.ndarray

    @staticmethod
    def zero() -> Inertia:
        return Inertia(0.0, np.zeros(3), np.zeros((3, 3)))

    def transformed(self, T: np.ndarray) -> Inertia:
        """The same body seen from a frame where this frame has pose `T` (4×4)."""
        R = T[:3, :3]
        return Inertia(self.mass, R @ self.com + T[:3, 3], R @ self.tensor @ R.T)


def from_inertial(inertial: Inertial | None) -> Inertia | None:
    """A description's inertial in its link frame (the origin's rotation turns the full tensor)."""
    if inertial is None:
        return None
    tensor = inertial.inertia
    local = Inertia(inertial.mass, np.zeros(3), tensor / 2 + tensor.T / 2)  # no overflow
    with np.errstate(over="ignore", invalid="ignore"):  # `out_of_range` names such values
        return local.transformed(inertial.origin)


def out_of_range(inertia: Inertia) -> str | None:
    """Why an inertia's numbers cannot be a body's (None if they can): NaN, infinite or huge.

    No repair applies: the values are not a physical body's to bound.
    """
    values = np.concatenate([[inertia.mass], inertia.com, np.ravel(inertia.tensor)])
    if not np.all(np.isfinite(values)):
        return "its <inertial> holds a value that is not a finite number"
    if np.max(np.abs(values)) > MAX_MAGNITUDE:
        return f"its <inertial> holds a value beyond {MAX_MAGNITUDE:g} (kg, kg m², m)"
    return None


def combine(parts: list[Inertia]) -> Inertia:
    """Merge inertias given in one frame (parallel-axis theorem), as sdformat lumps links."""
    mass = sum(p.mass for p in parts)
    if mass <= 0:
        return Inertia(0.0, np.zeros(3), sum((p.tensor for p in parts), np.zeros((3, 3))))
    com = sum((p.mass * p.com for p in parts), np.zeros(3)) / mass
    tensor = np.zeros((3, 3))
    for p in parts:
        d = p.com - com
        tensor += p.tensor + p.mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return Inertia(mass, com, tensor)


def problem(inertia: Inertia) -> str | None:
    """Why an inertia is not physical (None if it is). Checks mass > 0, PD, triangle rule."""
    if not np.isfinite(inertia.mass) or inertia.mass <= 0:
        return f"mass {inertia.mass:g} kg is not positive"
    moments = np.linalg.eigvalsh(inertia.tensor)
    scale = max(float(np.max(np.abs(moments))), 1e-300)
    if moments[0] <= REL_TOL * scale:
        return f"inertia tensor is not positive definite (principal moments {_fmt(moments)})"
    if moments[0] + moments[1] < moments[2] * (1 - REL_TOL):
        return f"principal moments {_fmt(moments)} break the triangle inequality (A + B ≥ C)"
    return None


def describe(inertia: Inertia) -> str:
    """The values for an error message: mass and the six tensor entries."""
    t = inertia.tensor
    return (
        f"mass={inertia.mass:g} ixx={t[0, 0]:g} iyy={t[1, 1]:g} izz={t[2, 2]:g} "
        f"ixy={t[0, 1]:g} ixz={t[0, 2]:g} iyz={t[1, 2]:g}"
    )


def repair_tensor(inertia: Inertia) -> Inertia:
    """Bound the principal moments: floor them and raise the small ones to meet A + B ≥ C.

    The principal axes are kept; only the moments change.
    """
    moments, axes = np.linalg.eigh(inertia.tensor)
    floor = max(REPAIR_MIN_ABS, REPAIR_MIN_REL * float(np.max(np.abs(moments))))
    moments = np.maximum(moments, floor)
    gap = moments[2] - moments[0] - moments[1]
    if gap > 0:
        moments[:2] += gap / 2
    return Inertia(inertia.mass, inertia.com, axes @ np.diag(moments) @ axes.T)


def from_box(lo: np.ndarray, hi: np.ndarray) -> Inertia:
    """A solid box of `REPAIR_DENSITY` spanning [lo, hi] [m] (used to repair massless links)."""
    size = np.maximum(hi - lo, 2 * REPAIR_FALLBACK_HALF)
    mass = max(REPAIR_DENSITY * float(np.prod(size)), REPAIR_FALLBACK_MASS)
    x, y, z = size**2
    tensor = mass / 12 * np.diag([y + z, x + z, x + y])
    return Inertia(mass, (lo + hi) / 2, tensor)


def principal(inertia: Inertia) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (3,) and the quaternion (w, x, y, z) of the principal axes."""
    import mujoco

    tensor = inertia.tensor
    off_diagonal = np.abs(tensor - np.diag(np.diag(tensor))).max()
    if off_diagonal <= DIAGONAL_TOL * max(np.abs(np.diag(tensor)).max(), 1e-300):
        # Already principal in the body frame: keep the URDF's axes, identity quaternion.
        return np.maximum(np.diag(tensor), 0.0), np.array([1.0, 0.0, 0.0, 0.0])
    moments, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(axes).reshape(-1))
    return np.maximum(moments, 0.0), quat


def _fmt(values: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:.4g}" for v in values) + "]"
