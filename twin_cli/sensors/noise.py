"""Gazebo's Gaussian sensor noise, drawn from a seeded generator so that runs are reproducible.

As Gazebo Classic's `GaussianNoiseModel` (and noise.sdf): when a sensor starts, a bias is drawn
from N(bias_mean, bias_stddev) and, with probability ½, negated (by convention bias_mean is
positive); each reading then becomes value + bias + N(mean, stddev). `gaussian_quantized` rounds
the result to a multiple of `precision`. One generator per sensor, seeded from the suite's seed
and the sensor's name, so adding a sensor never changes another's draws.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence

import numpy as np

from converters.description.sensors import Noise


def sensor_rng(seed: int, name: str) -> np.random.Generator:
    """The generator of sensor `name` under suite `seed` (independent streams per name)."""
    return np.random.default_rng([seed, zlib.crc32(name.encode())])


class NoiseSampler:
    """The noise of one sensor quantity: one `Noise` per axis (one for all rays of a scan)."""

    def __init__(self, noises: Sequence[Noise], rng: np.random.Generator) -> None:
        self.noises = tuple(noises)
        self.rng = rng
        self.active = np.array([n.active for n in self.noises])
        self.mean = np.array([n.mean for n in self.noises]) * self.active
        self.stddev = np.array([n.stddev for n in self.noises]) * self.active
        self.bias = np.array([self._draw_bias(n) for n in self.noises])
        self.precision = np.array(
            [n.precision if n.type == "gaussian_quantized" else 0.0 for n in self.noises]
        )

    def _draw_bias(self, noise: Noise) -> float:
        if not noise.active or (noise.bias_mean == 0.0 and noise.bias_stddev == 0.0):
            return 0.0
        bias = float(self.rng.normal(noise.bias_mean, noise.bias_stddev))
        return -bias if self.rng.random() < 0.5 else bias

    def apply(self, values: np.ndarray) -> np.ndarray:
        """`values` (…, axes) or (…,) for a single noise, with noise added; a new array."""
        if not self.active.any():
            return np.array(values, dtype=float)
        out = values + self.bias + self.mean + self.stddev * self.rng.standard_normal(values.shape)
        step = self.precision
        if step.any():
            quantized = np.round(out / np.where(step > 0, step, 1.0)) * step
            out = np.where(step > 0, quantized, out)
        return out
