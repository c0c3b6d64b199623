#!/usr/bin/env python3
"""OpenCV's stereoRectify on the pair of src/calib/stereo_rectify_tests.rs.

Prints R1, R2, P1, P2 and Q of cv2.stereoRectify (flags
CALIB_ZERO_DISPARITY, alpha -1: OpenCV's default scaling) for the test's
two Brown-Conrady cameras and right_from_left, as Rust arrays to paste into
the test (the oracle numbers there came from opencv-python-headless 5.1.0).

With a file argument (robocal's stereo OpenCV export, e.g.
fixtures/exports/stereo.opencv-yaml.stereo.opencv.yaml) it reads the file
with cv2.FileStorage instead and prints how far E, F and R1 R2 P1 P2 Q are
from [T]x R, K2^-T E K1^-1 and cv2.stereoRectify of the file's K, D, R, T
(with 5.1.0: E 7e-18, F 1e-20, R1 R2 4e-15, P1 P2 Q 1.5e-5 px).

Usage: python3 benches/stereo_rectify_opencv.py [FILE]   (needs cv2 and numpy)
"""
import sys
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


def check(path):
    fs = cv2.FileStorage(path, cv2.FILE_STORAGE_READ)
    k1, d1, k2, d2, r, e, f = (fs.getNode(k).mat() for k in ["K1", "D1", "K2", "D2", "R", "E", "F"])
    t = fs.getNode("T").mat()
    size = (int(fs.getNode("image_width").real()), int(fs.getNode("image_height").real()))
    tx = np.array([[0, -t[2, 0], t[1, 0]], [t[2, 0], 0, -t[0, 0]], [-t[1, 0], t[0, 0], 0]])
    print("E - [T]x R:", np.abs(e - tx @ r).max())
    print("F - K2^-T E K1^-1:", np.abs(f - np.linalg.inv(k2).T @ e @ np.linalg.inv(k1)).max())
    ours = [fs.getNode(k).mat() for k in ["R1", "R2", "P1", "P2", "Q"]]
    theirs = cv2.stereoRectify(k1, d1, k2, d2, size, r, t, flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1)[:5]
    for name, a, b in zip(["R1", "R2", "P1", "P2", "Q"], ours, theirs):
        print(f"{name} - cv2.stereoRectify:", np.abs(a - b).max())


if __name__ == "__main__":
    if len(sys.argv) > 1:
        check(sys.argv[1])
    else:
        main()
