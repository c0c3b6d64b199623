#!/usr/bin/env python3
"""OpenCV's stereoRectify on the pair of src/calib/stereo_rectify_tests.rs.

Prints R1, R2, P1, P2 and Q of cv2.stereoRectify (flags
CALIB_ZERO_DISPARITY, alpha -1: OpenCV's default scaling) for the test's
two Brown-Conrady cameras and right_from_left, as Rust arrays to paste into
the test (the oracle numbers there came from opencv-python-headless 5.1.0).

Usage: python3 bench/stereo_rectify_opencv.py   (needs cv2 and numpy)
"""
import cv2
import numpy as np


def camera(fx, cx, k1):
    k = np.array([[fx, 0.0, cx], [0.0, fx * 1.01, 241.0], [0.0, 0.0, 1.0]])
    d = np.array([k1, 0.01, 0.0005, -0.0003, 0.0])
    return k, d


def main():
    k1, d1 = camera(620.0, 318.0, -0.12)
    k2, d2 = camera(640.0, 326.0, -0.05)
    r, _ = cv2.Rodrigues(np.array([0.01, -0.04, 0.015]))
    t = np.array([[-0.06], [0.002], [-0.001]])
    r1, r2, p1, p2, q, _, _ = cv2.stereoRectify(
        k1, d1, k2, d2, (640, 480), r, t, flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1
    )
    for name, m in [("R1", r1), ("R2", r2), ("P1", p1), ("P2", p2), ("Q", q)]:
        values = ", ".join(repr(float(v)) for v in m.flatten())
        print(f"const OPENCV_{name}: [f64; {m.size}] = [{values}];")


if __name__ == "__main__":
    main()
