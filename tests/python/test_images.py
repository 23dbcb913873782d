"""penumbra_client.images: raw image buffers of the ZeroMQ protocol as numpy arrays."""

import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python"))
from penumbra_client.images import ImageFormatError, depth_mm_to_m, image_from_buffer  # noqa: E402


class ImageFromBufferTest(unittest.TestCase):
    def test_rgb8_rows_and_channels(self):
        h, w = 3, 4
        ref = np.arange(h * w * 3, dtype=np.uint8).reshape(h, w, 3)
        img = image_from_buffer(ref.tobytes(), w, h, "rgb8", step=w * 3)
        self.assertEqual(img.shape, (h, w, 3))
        self.assertEqual(img.dtype, np.uint8)
        np.testing.assert_array_equal(img, ref)
        # pixel (u, v) = (column, row) is img[v, u]: the first bytes are the top-left pixel
        self.assertEqual(tuple(img[0, 1]), (3, 4, 5))
        self.assertEqual(tuple(img[1, 0]), (12, 13, 14))
        self.assertFalse(img.flags.writeable)

    def test_packed_rows_share_memory(self):
        buf = bytearray(np.arange(24, dtype=np.uint8).tobytes())
        img = image_from_buffer(buf, 4, 2, "rgb8")
        buf[0] = 200
        self.assertEqual(img[0, 0, 0], 200)

    def test_padded_step_drops_the_padding(self):
        h, w, step = 2, 3, 12  # 3 padding bytes per row
        raw = np.full((h, step), 255, dtype=np.uint8)
        raw[:, :9] = np.arange(h * 9, dtype=np.uint8).reshape(h, 9)
        img = image_from_buffer(raw.tobytes(), w, h, "rgb8", step=step)
        np.testing.assert_array_equal(img.reshape(h, 9), raw[:, :9])
        self.assertFalse(np.any(img == 255))

    def test_depth_float32_metres(self):
        ref = np.array([[0.5, 1.25], [np.inf, 7.0]], dtype=np.float32)
        img = image_from_buffer(ref.tobytes(), 2, 2, "32FC1")
        self.assertEqual(img.dtype, np.float32)
        self.assertEqual(img.shape, (2, 2))
        np.testing.assert_array_equal(img, ref)

    def test_depth_uint16_mm_and_conversion(self):
        ref = np.array([[0, 500], [1250, 65535]], dtype="<u2")
        img = image_from_buffer(ref.tobytes(), 2, 2, "16UC1", step=4)
        self.assertEqual(img.dtype, np.uint16)
        np.testing.assert_array_equal(img, ref)
        m = depth_mm_to_m(img)
        self.assertEqual(float(m[0, 0]), 0.0)
        self.assertAlmostEqual(float(m[0, 1]), 0.5, places=6)
        self.assertAlmostEqual(float(m[1, 1]), 65.535, places=3)

    def test_big_endian_is_converted(self):
        ref = np.array([[1, 258]], dtype=">u2")
        img = image_from_buffer(ref.tobytes(), 2, 1, "16UC1", is_bigendian=True)
        np.testing.assert_array_equal(img, [[1, 258]])

    def test_errors_name_the_field(self):
        data = bytes(12)
        with self.assertRaisesRegex(ImageFormatError, "encoding: 'yuv422'"):
            image_from_buffer(data, 2, 2, "yuv422")
        with self.assertRaisesRegex(ImageFormatError, "width: 0"):
            image_from_buffer(data, 0, 2, "rgb8")
        with self.assertRaisesRegex(ImageFormatError, "height: '2'"):
            image_from_buffer(data, 2, "2", "rgb8")
        with self.assertRaisesRegex(ImageFormatError, "step: 5; expected an integer >= .* 6"):
            image_from_buffer(data, 2, 2, "rgb8", step=5)
        with self.assertRaisesRegex(ImageFormatError, "payload: 12 bytes; .* 16"):
            image_from_buffer(data, 2, 2, "32FC1")


if __name__ == "__main__":
    unittest.main()
