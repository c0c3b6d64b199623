#!/usr/bin/env python3
"""OpenCV's projection through the tilted (Scheimpflug) model, for the test
`camera::tests::the_tilted_model_projects_as_opencv` (issue 40).

Projects fixed camera-frame points through Camera::example_tilted()
(src/camera/examples.rs: fx 1000, fy 1002, cx 641.5, cy 478.25, no skew,
14 coefficients k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tauX tauY) with
cv2.projectPoints (opencv-python-headless 4.14.0.94, benches/opencv_venv.py),
with the thin-prism and rational terms set to non-zero values so that every
term is exercised, and prints the pixels with 17 significant digits.

Usage: python3 benches/tilted_opencv.py
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from opencv_venv import ensure_venv  # noqa: E402

ensure_venv()
import cv2  # noqa: E402
import numpy as np  # noqa: E402

K = np.array([[1000.0, 0.0, 641.5], [0.0, 1002.0, 478.25], [0.0, 0.0, 1.0]])
# k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tauX tauY
D = np.array([-0.21, 0.07, 0.0008, -0.0005, -0.008, 0.02, -0.003, 0.001,
              0.0011, -0.0002, 0.0006, 0.0001, 0.052, -0.035])
P = np.array([[0.0, 0.0, 1.0], [0.3, -0.2, 1.0], [-0.25, 0.35, 0.8],
              [0.5, 0.4, 2.0], [-0.6, -0.45, 1.5]])
px, _ = cv2.projectPoints(P, np.zeros(3), np.zeros(3), K, D)
for p, q in zip(P, px.reshape(-1, 2)):
    print(f"([{p[0]}, {p[1]}, {p[2]}], [{q[0]:.17g}, {q[1]:.17g}]),")
