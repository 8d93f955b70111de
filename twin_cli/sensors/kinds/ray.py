"""Lidar (`ray`, `gpu_ray`, `lidar`, `gpu_lidar`): MuJoCo ray casting from the sensor's site.

Gazebo casts each ray over the segment [range_min, range_max] from the sensor origin against
collision shapes, so anything nearer than range_min is not seen (the ray goes on) and the
robot's own shell around its lidar does not blind it. twin casts all rays at once with
`mj_multiRay` (excluding the sensor's body, and visual geoms: MuJoCo group 2 holds twin's
visuals) and re-casts, past the hit, the few rays that hit another body of the same entity,
a non-colliding geom or something nearer than range_min. As Gazebo Classic then does (REP 117),
a ray with no hit up to range_max reads +inf; the others get noise and are clamped to
[range_min, range_max]. Ray directions: horizontal angle about the sensor's z, vertical angle
up from its x-y plane, `samples × resolution` rays evenly from min to max angle.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from converters.description.sensors import RaySpec
from twin_cli.sensors.frames import body_id, entity_bodies, site_id
from twin_cli.sensors.noise import NoiseSampler
from twin_cli.sensors.readings import ScanReading
from twin_cli.sensors.registry import sensor_for

VISUAL_GROUP = 2  # converters.mjcf.builder.VISUAL_GROUP: visual-only geoms
GEOM_GROUPS = np.array([g != VISUAL_GROUP for g in range(6)], dtype=np.uint8)
MAX_RECASTS = 16  # passes through skipped geoms per ray before giving up (reads +inf)
STEP_PAST = 1e-9  # [m] restart a re-cast this far past the skipped hit


def ray_angles(spec: RaySpec) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal and vertical ray angles [rad] (evenly spaced, ends included)."""

    def spread(lo: float, hi: float, n: int) -> np.ndarray:
        return np.array([lo]) if n == 1 else np.linspace(lo, hi, n)

    horizontal = spread(spec.horizontal_min_angle, spec.horizontal_max_angle, spec.horizontal_rays)
    vertical = spread(spec.vertical_min_angle, spec.vertical_max_angle, spec.vertical_rays)
    return horizontal, vertical


def ray_directions(spec: RaySpec) -> np.ndarray:
    """Unit directions (n×3) in the sensor frame, rows of the lowest vertical angle first."""
    horizontal, vertical = ray_angles(spec)
    v, h = np.meshgrid(vertical, horizontal, indexing="ij")
    dirs = np.stack([np.cos(v) * np.cos(h), np.cos(v) * np.sin(h), np.sin(v)], axis=-1)
    return dirs.reshape(-1, 3)


@sensor_for(RaySpec, kinematic=True)
class RaySensor:
    """One lidar of an entity."""

    def __init__(self, spec: RaySpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.noise = NoiseSampler((spec.noise,), rng)
        self.local_dirs = ray_directions(spec)
        self.site = self.body = -1
        self.own: frozenset[int] = frozenset()
        self.passive = np.zeros(0, bool)
        self.skip = np.zeros(0, bool)  # by geom: the entity's own or non-colliding
        horizontal, _ = ray_angles(spec)
        self.angle_min, self.angle_max = float(horizontal[0]), float(horizontal[-1])
        self.increment = float(horizontal[1] - horizontal[0]) if len(horizontal) > 1 else 0.0

    def bind(self, model: mujoco.MjModel) -> None:
        self.site = site_id(model, self.entity, self.spec.site)
        self.body = body_id(model, self.entity, self.spec.body)
        self.own = entity_bodies(model, self.entity)
        self.passive = (model.geom_contype == 0) & (model.geom_conaffinity == 0)
        own = np.isin(model.geom_bodyid, list(self.own))
        self.skip = own | self.passive

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> ScanReading:
        ranges = self.ranges(model, data)
        hit = np.isfinite(ranges)
        noisy = np.clip(self.noise.apply(ranges[hit]), self.spec.range_min, self.spec.range_max)
        ranges[hit] = noisy
        rate = self.spec.update_rate
        return ScanReading(
            self.spec.name,
            self.spec.type,
            time,
            self.spec.frame_id,
            self.angle_min,
            self.angle_max,
            self.increment,
            1.0 / rate if rate > 0 else model.opt.timestep,
            self.spec.range_min,
            self.spec.range_max,
            tuple(ranges.tolist()),
            self.spec.vertical_rays,
        )

    def ranges(self, model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
        """Noise-free ranges [m] of every ray, +inf where nothing is within range_max."""
        origin = data.site_xpos[self.site].copy()
        dirs = self.local_dirs @ data.site_xmat[self.site].reshape(3, 3).T
        n = len(dirs)
        geoms = np.full(n, -1, np.int32)
        dist = np.full(n, -1.0)
        cutoff = self.spec.range_max
        mujoco.mj_multiRay(
            model, data, origin, dirs.reshape(-1), GEOM_GROUPS, 1, self.body, geoms, dist, None,
            n, cutoff,
        )  # fmt: skip
        for i in np.flatnonzero(self._skipped(model, geoms, dist)):
            dist[i], geoms[i] = self._recast(model, data, origin, dirs[i], dist[i], geoms[i])
        return np.where((geoms >= 0) & (dist <= cutoff), dist, math.inf)

    def _skipped(self, model: mujoco.MjModel, geoms: np.ndarray, dist: np.ndarray) -> np.ndarray:
        hit = geoms >= 0
        return hit & (self.skip[np.where(hit, geoms, 0)] | (dist < self.spec.range_min))

    def _recast(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        origin: np.ndarray,
        direction: np.ndarray,
        t: float,
        geom: int,
    ) -> tuple[float, int]:
        """Continue one ray past hits it must not see; (distance, geom) or (−1, −1)."""
        found = np.array([-1], np.int32)
        for _ in range(MAX_RECASTS):
            start = origin + (t + STEP_PAST) * direction
            body = int(model.geom_bodyid[geom])
            exclude = body if body > 0 else -1  # excluding body 0 would hide the whole scene
            more = mujoco.mj_ray(model, data, start, direction, GEOM_GROUPS, 1, exclude, found)
            if found[0] < 0:
                return -1.0, -1
            t, geom = t + STEP_PAST + more, int(found[0])
            if not self._skipped(model, np.array([geom]), np.array([t]))[0]:
                return t, geom
        return -1.0, -1
