"""penumbra_client.spaces: Gymnasium-shaped Box and Dict spaces without gymnasium."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python"))
from penumbra_client.spaces import Box, Dict  # noqa: E402


class BoxTest(unittest.TestCase):
    def test_bounds_broadcast_and_contains(self):
        box = Box(-1.0, [1.0, 2.0, 3.0], shape=(3,))
        np.testing.assert_array_equal(box.low, [-1, -1, -1])
        np.testing.assert_array_equal(box.high, [1, 2, 3])
        self.assertTrue(box.contains([0.0, 2.0, -1.0]))
        self.assertFalse(box.contains([0.0, 2.1, 0.0]))
        self.assertFalse(box.contains([0.0, 0.0]))
        self.assertFalse(box.contains([np.nan, 0.0, 0.0]))

    def test_samples_lie_inside_and_are_seeded(self):
        box = Box([-0.5, 0.0], [0.5, 10.0])
        a = [box.sample(np.random.default_rng(4)) for _ in range(3)]
        b = [box.sample(np.random.default_rng(4)) for _ in range(3)]
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)
        rng = np.random.default_rng(1)
        self.assertTrue(all(box.contains(box.sample(rng)) for _ in range(200)))

    def test_image_box(self):
        img = Box(0, 255, shape=(6, 8, 3), dtype=np.uint8)
        x = img.sample(np.random.default_rng(0))
        self.assertEqual(x.dtype, np.uint8)
        self.assertEqual(x.shape, (6, 8, 3))
        self.assertTrue(img.contains(x))

    def test_unbounded_box_samples_finite(self):
        box = Box(-np.inf, np.inf, shape=(4,))
        self.assertTrue(np.all(np.isfinite(box.sample(np.random.default_rng(0)))))

    def test_low_above_high_is_refused(self):
        with self.assertRaises(ValueError):
            Box([1.0], [0.0])


class DictTest(unittest.TestCase):
    def test_contains_and_sample(self):
        space = Dict({"qpos": Box(-np.inf, np.inf, shape=(2,)),
                      "rgb": Box(0, 255, (2, 2, 3), np.uint8)})
        x = space.sample(np.random.default_rng(0))
        self.assertEqual(set(x), {"qpos", "rgb"})
        self.assertTrue(space.contains(x))
        del x["rgb"]
        self.assertFalse(space.contains(x))
        self.assertEqual(space["qpos"].shape, (2,))


if __name__ == "__main__":
    unittest.main()
