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

BLOCK = 256  # readings of normals drawn at once by `apply_one`


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
        self._offset = self.bias + self.mean
        self._block = np.empty((0, len(self.noises)))
        self._row = 0
        self._any, self._quantized = bool(self.active.any()), bool(self.precision.any())

    def _draw_bias(self, noise: Noise) -> float:
        if not noise.active or (noise.bias_mean == 0.0 and noise.bias_stddev == 0.0):
            return 0.0
        bias = float(self.rng.normal(noise.bias_mean, noise.bias_stddev))
        return -bias if self.rng.random() < 0.5 else bias

    def apply_one(self, values: np.ndarray) -> np.ndarray:
        """One reading (a vector of one value per axis) with noise added; a new array.

        The same law as `apply`, drawn from a block of BLOCK pre-drawn normals: a reading costs
        a row, not a call into the generator (a 200 Hz IMU reads at most a few µs of Python).
        """
        if not self._any:
            return np.array(values, dtype=float)
        if self._row >= len(self._block):
            self._block = self.rng.standard_normal((BLOCK, len(self.noises)))
            self._row = 0
        out = values + self._offset + self.stddev * self._block[self._row]
        self._row += 1
        if self._quantized:
            return self._quantize(out)
        return out

    def _quantize(self, out: np.ndarray) -> np.ndarray:
        step = self.precision
        quantized = np.round(out / np.where(step > 0, step, 1.0)) * step
        return np.where(step > 0, quantized, out)

    def apply(self, values: np.ndarray) -> np.ndarray:
        """`values` (…, axes) or (…,) for a single noise, with noise added; a new array."""
        if not self.active.any():
            return np.array(values, dtype=float)
        out = values + self.bias + self.mean + self.stddev * self.rng.standard_normal(values.shape)
        if self.precision.any():
            return self._quantize(out)
        return out
