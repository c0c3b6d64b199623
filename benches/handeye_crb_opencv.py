#!/usr/bin/env python3
"""OpenCV 4.14 on the trials of the hand-eye Cramér-Rao benchmark.

The Rust example writes every trial (noisy robot poses, PnP camera poses,
true X) and robocal's refined error:
  cargo run --release --example handeye_crb -- --trials-json /tmp/crb.json
This script feeds the same poses to cv2.calibrateHandEye (5 methods) and
cv2.calibrateRobotWorldHandEye (Shah, Li), and prints per scenario the mean
X error of OpenCV's best method (by mean translation error, and by mean
rotation error) next to robocal's refined estimate.

Usage: python3 benches/handeye_crb_opencv.py /tmp/crb.json
It runs in benches/.venv (opencv-python-headless==4.14.0.94, benches/opencv_venv.py).
"""
import json
import sys

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402
import numpy as np  # noqa: E402

from compare_handeye import errors, opencv  # noqa: E402

cv2.setNumThreads(1)


def main():
    with open(sys.argv[1]) as f:
        scenarios = json.load(f)
    print(f"OpenCV {cv2.__version__}: mean X error, rotation deg / translation mm\n")
    print("| scenario | robocal refined | OpenCV best (translation) | OpenCV best (rotation) |")
    print("|---|---|---|---|")
    for sc in scenarios:
        res = {}
        for trial in sc["trials"]:
            x = np.array(trial["x_true"])
            robot = [np.array(m) for m in trial["base_from_gripper"]]
            camera = [np.array(m) for m in trial["camera_from_target"]]
            for name, est in opencv(sc["setup"], robot, camera).items():
                res.setdefault(name, []).append(errors(est, x))
        means = {k: np.nanmean(np.array(v), axis=0) for k, v in res.items()}
        best_t = min(means, key=lambda k: means[k][1])
        best_r = min(means, key=lambda k: means[k][0])
        r, t = sc["refined_mean"]
        print(f"| {sc['name']} | {r:.4f} / {t:.3f} | {best_t}: {means[best_t][0]:.4f} / "
              f"{means[best_t][1]:.3f} | {best_r}: {means[best_r][0]:.4f} / {means[best_r][1]:.3f} |")


if __name__ == "__main__":
    main()
