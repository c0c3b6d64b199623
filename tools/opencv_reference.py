#!/usr/bin/env python3
"""Record OpenCV's projections as a fixture for robocal's camera models.

Writes fixtures/opencv_project_points.json: for a Brown (5-coefficient),
a rational + thin-prism (12-coefficient) and a fisheye camera, seeded random
camera-frame points and the pixels cv2.projectPoints /
cv2.fisheye.projectPoints give for them (identity pose, so the inputs are
camera-frame points as robocal's Camera::project takes them).

Usage (creates benches/.venv with the pinned OpenCV on first run, see
benches/opencv_venv.py):
    python3 tools/opencv_reference.py
The reference is opencv-python-headless==4.14.0.94 (see issue 5).
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(ROOT, "fixtures", "opencv_project_points.json")

sys.path.insert(0, os.path.join(ROOT, "benches"))
from opencv_venv import ensure_venv  # noqa: E402  (the shared benches/.venv)


def random_points(rng, n, max_angle_deg):
    """Points at depth 0.5..5 m within max_angle_deg of the optical axis."""
    import numpy as np

    angle = np.radians(rng.uniform(0.0, max_angle_deg, n))
    azimuth = rng.uniform(-np.pi, np.pi, n)
    depth = rng.uniform(0.5, 5.0, n)
    direction = np.stack(
        [np.sin(angle) * np.cos(azimuth), np.sin(angle) * np.sin(azimuth), np.cos(angle)], axis=1
    )
    return direction * (depth / direction[:, 2])[:, None]


def main():
    ensure_venv()
    import cv2
    import numpy as np

    cv2.setNumThreads(1)
    rng = np.random.default_rng(20240607)
    zero = np.zeros(3)
    cases = []

    def pinhole_k(fx, fy, cx, cy, skew=0.0):
        return np.array([[fx, skew, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])

    polynomial = [
        ("brown", pinhole_k(1000.0, 1002.0, 641.5, 478.25),
         [-0.28, 0.09, 0.0012, -0.0007, -0.012], 35.0),
        ("rational", pinhole_k(1000.0, 1002.0, 641.5, 478.25),
         [0.25, -0.04, 0.0009, -0.0004, 0.01, 0.55, 0.03, 0.002,
          0.0011, -0.0002, 0.0006, 0.0001], 35.0),
    ]
    for model, k, dist, max_angle in polynomial:
        points = random_points(rng, 200, max_angle)
        pixels, _ = cv2.projectPoints(points.reshape(-1, 1, 3), zero, zero, k, np.array(dist))
        cases.append({
            "model": model,
            "camera_matrix_row_major": k.flatten().tolist(),
            "opencv_dist_coeffs": dist,
            "points_camera_m": points.tolist(),
            "pixels_px": pixels.reshape(-1, 2).tolist(),
        })

    # cv::fisheye's alpha is the skew relative to fx: u = fx (x + alpha y) + cx.
    k = pinhole_k(420.0, 419.5, 639.0, 481.0)
    alpha = 0.3 / 420.0
    dist = [0.045, -0.012, 0.0021, -0.0004]
    points = random_points(rng, 200, 85.0)
    pixels, _ = cv2.fisheye.projectPoints(
        points.reshape(-1, 1, 3), zero, zero, k, np.array(dist), alpha=alpha
    )
    cases.append({
        "model": "kannala_brandt",
        "camera_matrix_row_major": k.flatten().tolist(),
        "fisheye_alpha": alpha,
        "opencv_dist_coeffs": dist,
        "points_camera_m": points.tolist(),
        "pixels_px": pixels.reshape(-1, 2).tolist(),
    })

    fixture = {
        "generator": "tools/opencv_reference.py",
        "opencv_version": cv2.__version__,
        "numpy_version": np.__version__,
        "note": "identity pose: points are in the camera frame; pixel (0,0) is the centre of the top-left pixel",
        "cases": cases,
    }
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump(fixture, f, separators=(",", ":"))
        f.write("\n")
    print(f"wrote {OUT}: {sum(len(c['pixels_px']) for c in cases)} points in {len(cases)} cases")


if __name__ == "__main__":
    main()
