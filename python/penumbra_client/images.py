"""Image buffers of the ZeroMQ protocol as numpy arrays.

An image travels as a header (width, height, step, encoding, ...) and a raw payload of
``height * step`` bytes, rows top to bottom, pixels left to right (the image layout of
ROS ``sensor_msgs/Image``). :func:`image_from_buffer` turns the pair into a numpy array
without copying when the rows are tightly packed:

============  ===============  =======================================================
encoding      numpy result     meaning
============  ===============  =======================================================
``rgb8``      uint8 (H, W, 3)  8-bit sRGB, R G B per pixel
``rgba8``     uint8 (H, W, 4)  8-bit sRGB plus alpha
``bgr8``      uint8 (H, W, 3)  8-bit sRGB, B G R per pixel (returned as stored)
``mono8``     uint8 (H, W)     8-bit grey
``mono16``    uint16 (H, W)    16-bit grey
``8UC1``      uint8 (H, W)     one unsigned byte per pixel
``16UC1``     uint16 (H, W)    e.g. depth in millimetres (0 = no return)
``32SC1``     int32 (H, W)     e.g. segmentation ids
``32FC1``     float32 (H, W)   e.g. depth in metres (z along the optical axis)
``32FC3``     float32 (H,W,3)  e.g. unit normals in the camera's optical frame
============  ===============  =======================================================

Pixel (u, v) = (column, row) is ``array[v, u]``; (0, 0) is the centre of the top-left
pixel (OpenCV convention, as in docs/world-file.md).
"""

from __future__ import annotations

import numpy as np

# encoding -> (numpy scalar type, channels)
ENCODINGS = {
    "rgb8": (np.uint8, 3),
    "rgba8": (np.uint8, 4),
    "bgr8": (np.uint8, 3),
    "bgra8": (np.uint8, 4),
    "mono8": (np.uint8, 1),
    "mono16": (np.uint16, 1),
    "8UC1": (np.uint8, 1),
    "8UC3": (np.uint8, 3),
    "16UC1": (np.uint16, 1),
    "32SC1": (np.int32, 1),
    "32FC1": (np.float32, 1),
    "32FC3": (np.float32, 3),
    "64FC1": (np.float64, 1),
}


class ImageFormatError(ValueError):
    """A header/payload pair that does not describe a valid image (the message says which
    field and what was expected)."""


def image_from_buffer(payload, width, height, encoding, step=None, is_bigendian=False):
    """Returns the image in ``payload`` as a numpy array (see the module docstring).

    :param payload: bytes-like (``bytes``, ``memoryview``, ``zmq.Frame.buffer``) of at least
        ``height * step`` bytes.
    :param width: pixels per row (> 0).
    :param height: rows (> 0).
    :param encoding: one of :data:`ENCODINGS`.
    :param step: bytes per row (>= width * pixel size); default: tightly packed.
    :param is_bigendian: multi-byte pixels are big-endian (default little-endian).
    :returns: an array of shape (height, width) for one channel, (height, width, C) for C
        channels. It is read-only and shares memory with ``payload`` where possible.
    :raises ImageFormatError: unknown encoding, non-positive size, a step shorter than a
        row, or a payload shorter than ``height * step``.
    """
    if encoding not in ENCODINGS:
        raise ImageFormatError(
            f"encoding: '{encoding}' is not supported; expected one of {sorted(ENCODINGS)}")
    for name, value in (("width", width), ("height", height)):
        if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value <= 0:
            raise ImageFormatError(f"{name}: {value!r}; expected a positive integer")
    scalar, channels = ENCODINGS[encoding]
    dtype = np.dtype(scalar).newbyteorder(">" if is_bigendian else "<")
    row_bytes = width * channels * dtype.itemsize
    if step is None:
        step = row_bytes
    if not isinstance(step, (int, np.integer)) or isinstance(step, bool) or step < row_bytes:
        raise ImageFormatError(
            f"step: {step!r}; expected an integer >= width * bytes per pixel = {row_bytes}")
    view = memoryview(payload).cast("B")
    if len(view) < height * step:
        raise ImageFormatError(
            f"payload: {len(view)} bytes; expected at least height * step = {height * step}")
    rows = np.frombuffer(view, dtype=np.uint8, count=height * step).reshape(height, step)
    pixels = rows[:, :row_bytes]
    if step != row_bytes:
        pixels = np.ascontiguousarray(pixels)
    image = pixels.view(dtype).reshape((height, width, channels) if channels > 1 else
                                       (height, width))
    if is_bigendian == np.little_endian and dtype.itemsize > 1:
        image = image.astype(dtype.newbyteorder("="))
    image.flags.writeable = False
    return image


def depth_mm_to_m(depth_mm):
    """uint16 depth in millimetres (``depth_mm``) -> float32 metres; 0 (no hit) stays 0, as
    in the ``depth`` output."""
    return np.asarray(depth_mm).astype(np.float32) / np.float32(1000.0)
