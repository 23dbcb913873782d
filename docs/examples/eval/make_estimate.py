#!/usr/bin/env python3
"""writes docs/examples/eval/estimate.txt: a synthetic "SLAM estimate" of groundtruth.txt for
the example in docs/evaluation.md (not the output of any real estimator).

what it does to the ground truth, so that `penumbra eval` has something to find:
- expresses it in another frame at half scale (a monocular estimate): p_V = 0.5 R^T (p_W - t)
  with R = Rz(40 deg) Rx(5 deg), t = (1, -2, 0.3) m; orientations R^T R_WB;
- adds a drift of 1 cm/s along the estimate's x axis, Gaussian noise of 4 mm per axis and 0.5 deg
  per axis on the orientation;
- drops the poses from 8 s to 10 s (a tracking loss);
- stamps each pose 0 .. 4 ms late (uniform).
standard library only; seeded, so the output is the same on every run:

  python3 docs/examples/eval/make_estimate.py docs/examples/eval/groundtruth.txt \
      > docs/examples/eval/estimate.txt
"""

import math
import random
import sys


def qmul(a, b):
    """Hamilton product of (w, x, y, z) quaternions."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def qaxis(axis, angle_rad):
    n = math.sqrt(sum(c * c for c in axis))
    s = math.sin(angle_rad / 2) / n
    return (math.cos(angle_rad / 2), axis[0] * s, axis[1] * s, axis[2] * s)


def qconj(q):
    return (q[0], -q[1], -q[2], -q[3])


def rotate(q, v):
    w = qmul(qmul(q, (0.0, v[0], v[1], v[2])), qconj(q))
    return (w[1], w[2], w[3])


def main():
    rng = random.Random(18)
    scale = 0.5
    q_R = qmul(qaxis((0, 0, 1), math.radians(40)), qaxis((1, 0, 0), math.radians(5)))
    t = (1.0, -2.0, 0.3)
    print("# synthetic estimate of groundtruth.txt (docs/examples/eval/make_estimate.py)")
    print("# timestamp tx ty tz qx qy qz qw")
    t0 = None
    for line in open(sys.argv[1]):
        f = line.replace(",", " ").split()
        if not f or f[0].startswith("#"):
            continue
        time = float(f[0])
        t0 = time if t0 is None else t0
        if 8.0 <= time - t0 < 10.0:
            continue
        p = [float(x) for x in f[1:4]]
        q = (float(f[7]), float(f[4]), float(f[5]), float(f[6]))
        p_v = rotate(qconj(q_R), [p[i] - t[i] for i in range(3)])
        p_v = [scale * c for c in p_v]
        p_v[0] += 0.01 * (time - t0)
        p_v = [c + rng.gauss(0, 0.004) for c in p_v]
        noise = qmul(qmul(qaxis((1, 0, 0), math.radians(rng.gauss(0, 0.5))),
                          qaxis((0, 1, 0), math.radians(rng.gauss(0, 0.5)))),
                     qaxis((0, 0, 1), math.radians(rng.gauss(0, 0.5))))
        q_v = qmul(noise, qmul(qconj(q_R), q))
        stamp = time + rng.uniform(0, 0.004)
        print(f"{stamp:.6f} {p_v[0]:.6f} {p_v[1]:.6f} {p_v[2]:.6f} "
              f"{q_v[1]:.6f} {q_v[2]:.6f} {q_v[3]:.6f} {q_v[0]:.6f}")


if __name__ == "__main__":
    main()
