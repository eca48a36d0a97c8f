"""Minimal action and observation space descriptions, shaped like Gymnasium's.

gymnasium is not a dependency (it is not packaged by Debian); these two classes
carry what its spaces carry for autumnc's environments: ``Discrete(n)`` for the
integer actions and ``Box`` for uint8 colour-id observations.
"""
import numpy as np


class Discrete:
    """Integers 0..n-1."""

    def __init__(self, n, seed=None):
        self.n = int(n)
        self.shape = ()
        self.dtype = np.int64
        self._rng = np.random.default_rng(seed)

    def sample(self):
        return int(self._rng.integers(self.n))

    def seed(self, seed=None):
        self._rng = np.random.default_rng(seed)

    def contains(self, x):
        return isinstance(x, (int, np.integer)) and 0 <= int(x) < self.n

    def __repr__(self):
        return f"Discrete({self.n})"


class Box:
    """Arrays of ``shape`` with values in [low, high]."""

    def __init__(self, low, high, shape, dtype=np.uint8):
        self.low, self.high, self.shape, self.dtype = low, high, tuple(shape), np.dtype(dtype)

    def contains(self, x):
        x = np.asarray(x)
        return x.shape == self.shape and x.dtype == self.dtype and bool(((x >= self.low) & (x <= self.high)).all())

    def __repr__(self):
        return f"Box({self.low}, {self.high}, {self.shape}, {self.dtype})"
