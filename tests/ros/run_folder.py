"""a run folder read by the ROS tests (tests/ros/ bag and bridge tests): its PNG images, decoded by
Pillow, its CSV files, and the state samples a bridge or export makes of it."""
import csv
import os
import struct

from PIL import Image


def read_png(path):
    """(width, height, channels, bit depth, samples) of an 8-bit grey or RGB, or a 16-bit grey
    PNG: samples are the bytes of an 8-bit image, the integers of a 16-bit one, row by row."""
    with Image.open(path) as im:
        assert im.format == "PNG", path
        w, h = im.size
        if im.mode in ("L", "RGB"):
            return w, h, len(im.mode), 8, im.tobytes()
        if im.mode == "I;16":  # Pillow >= 10: 16-bit grey, little-endian raw
            return w, h, 1, 16, struct.unpack("<%dH" % (w * h), im.tobytes())
        if im.mode == "I":  # older Pillow: 16-bit grey widened to 32-bit
            return w, h, 1, 16, struct.unpack("=%di" % (w * h), im.tobytes())
        raise AssertionError("%s: unexpected PNG mode %s" % (path, im.mode))


def csv_rows(run_dir, path):
    """the rows of a CSV file of the run folder, as dicts by column name."""
    with open(os.path.join(run_dir, path)) as f:
        return list(csv.DictReader(f))


def state_samples(run_dir, rate_hz=50.0):
    """how many odometry / joint-state / tf samples a bridge or export makes at `rate_hz` from
    the run's trajectory.csv: the first physics step at or after each k / rate_hz."""
    n, k = 0, 0
    for row in csv_rows(run_dir, "trajectory.csv"):
        t = float(row["time_sec"])
        if t < k / rate_hz:
            continue
        while k / rate_hz <= t:
            k += 1
        n += 1
    return n
