"""Observation and action spaces in the shape of Gymnasium's, without needing gymnasium.

:class:`Box` mirrors ``gymnasium.spaces.Box`` (``low``, ``high``, ``shape``, ``dtype``,
``sample()``, ``contains()``) and :class:`Dict` mirrors ``gymnasium.spaces.Dict``, so code
written against Gymnasium reads these the same way. :func:`to_gymnasium` converts them when
gymnasium is installed.
"""

from __future__ import annotations

import numpy as np


class Box:
    """A box in R^n (or an integer lattice): every element lies in [low, high].

    :param low: lower bound, a scalar or an array of ``shape``.
    :param high: upper bound, a scalar or an array of ``shape``.
    :param shape: the shape of an element; default: the shape of ``low``.
    :param dtype: numpy element type (e.g. ``np.float64`` for ctrl, ``np.uint8`` for images).
    """

    def __init__(self, low, high, shape=None, dtype=np.float64):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.shape(low)
        self.shape = tuple(int(n) for n in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high):
            raise ValueError("Box: low > high in some element")

    def contains(self, x):
        """True when ``x`` has this shape and every element lies within [low, high]."""
        x = np.asarray(x)
        if x.shape != self.shape:
            return False
        if np.issubdtype(self.dtype, np.floating) and np.any(np.isnan(x)):
            return False
        return bool(np.all(x >= self.low) and np.all(x <= self.high))

    def sample(self, rng=None):
        """A uniform sample (bounds that are infinite are replaced by a unit normal draw).

        :param rng: a ``numpy.random.Generator`` (default: a new unseeded one).
        """
        rng = rng if rng is not None else np.random.default_rng()
        if np.issubdtype(self.dtype, np.integer):
            return rng.integers(self.low, self.high, endpoint=True, dtype=self.dtype)
        finite = np.isfinite(self.low) & np.isfinite(self.high)
        u = rng.uniform(np.where(finite, self.low, 0), np.where(finite, self.high, 1))
        return np.where(finite, u, rng.standard_normal(self.shape)).astype(self.dtype)

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape and
                self.dtype == other.dtype and np.array_equal(self.low, other.low) and
                np.array_equal(self.high, other.high))


class Dict:
    """A mapping of names to spaces (``spaces[name]``), like ``gymnasium.spaces.Dict``."""

    def __init__(self, spaces):
        self.spaces = dict(spaces)

    def __getitem__(self, key):
        return self.spaces[key]

    def __iter__(self):
        return iter(self.spaces)

    def keys(self):
        return self.spaces.keys()

    def items(self):
        return self.spaces.items()

    def contains(self, x):
        """True when ``x`` is a mapping with exactly these keys, each value in its space."""
        return (isinstance(x, dict) and set(x) == set(self.spaces) and
                all(self.spaces[k].contains(v) for k, v in x.items()))

    def sample(self, rng=None):
        rng = rng if rng is not None else np.random.default_rng()
        return {k: s.sample(rng) for k, s in self.spaces.items()}

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k}: {v!r}" for k, v in self.spaces.items()) + ")"


def to_gymnasium(space):
    """The same space as a ``gymnasium.spaces`` object (needs gymnasium installed)."""
    import gymnasium  # noqa: imported only on request

    if isinstance(space, Box):
        return gymnasium.spaces.Box(space.low, space.high, space.shape, space.dtype)
    if isinstance(space, Dict):
        return gymnasium.spaces.Dict({k: to_gymnasium(v) for k, v in space.items()})
    raise TypeError(f"not a penumbra_client space: {space!r}")
