#!/usr/bin/env python3
"""ChArUco hand-eye from rendered images: robocal's image path against
OpenCV 4.14 on the same images and robot poses (issue 18).

`cargo run --release --example handeye_charuco -- OUT` renders the sets
(eye-in-hand and eye-to-hand, 12x9 ChArUco DICT_5X5_100 with 20 mm squares
at about 0.45 m, 1280x960, every fourth view partial, robot pose noise
0.02 deg / 0.1 mm per axis; see the example's header). Per trial:

- robocal: `robocal detect --target SPEC view_*.png -o detections.json`, then
  `robocal handeye --setup S --poses poses.txt --pose-format matrix --camera
  camera.json --detections detections.json [--refine MODE]` (the same path
  as images on the command line: PnP per view, every closed form, then the
  refinement) without --refine (the default, `none`: the maximum likelihood
  over the poses with each view's PnP covariance: "robocal") and with MODE
  trusted and stochastic (over the pixels); the closed forms of the default
  run as "robocal <method>";
- OpenCV: `cv2.aruco.CharucoDetector.detectBoard` per image, `cv2.solvePnP`
  (SOLVEPNP_ITERATIVE, the true camera, no distortion) on the board's own
  corner positions, then `cv2.calibrateHandEye` (5 methods; eye-to-hand gets
  the inverted robot poses, as OpenCV documents) and
  `cv2.calibrateRobotWorldHandEye` (Shah, Li). A view with fewer than 6
  corners is dropped with its pose.

Printed: per setup and method the mean and median rotation (deg) and
translation (mm) error of X (gripper_from_camera / base_from_camera)
against the rendered truth.

Usage (crate root, after `make cli`):
  python3 benches/compare_handeye_charuco.py [--trials 20] [--views 12] [--skip-render]
It runs in benches/.venv (opencv-python-headless==4.14.0.94, benches/opencv_venv.py).
"""
import glob
import json
import os
import platform
import subprocess
import sys

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402
import numpy as np  # noqa: E402

from compare_handeye import errors, opencv  # noqa: E402

cv2.setNumThreads(1)
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out", "handeye_charuco")
ROBOCAL = os.path.join(ROOT, "target", "release", "robocal")
SPEC = "charuco:12x9:20mm:15mm:DICT_5X5_100"
# None: the default with images (`none`, the ML over the poses with each
# view's PnP covariance, robot noise estimated); trusted: refined over the
# pixels, robot poses exact; stochastic: robot pose noise estimated too.
REFINE_MODES = [None, "trusted", "stochastic"]


def arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def read_matrices(path):
    with open(path) as f:
        return [np.array([float(v) for v in line.split()]).reshape(4, 4)
                for line in f if line.strip()]


def opencv_trial(setup, images, robot, camera_json):
    board = cv2.aruco.CharucoBoard((12, 9), 0.020, 0.015,
                                   cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_5X5_100))
    det = cv2.aruco.CharucoDetector(board)
    k = np.array([[camera_json["fx"], 0.0, camera_json["cx"]],
                  [0.0, camera_json["fy"], camera_json["cy"]], [0.0, 0.0, 1.0]])
    object_all = board.getChessboardCorners()
    used_robot, camera = [], []
    for path, pose in zip(images, robot):
        grey = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        corners, ids, _, _ = det.detectBoard(grey)
        if ids is None or len(ids) < 6:
            continue
        ok, rvec, tvec = cv2.solvePnP(object_all[ids.ravel()], corners, k, None,
                                      flags=cv2.SOLVEPNP_ITERATIVE)
        if not ok:
            continue
        m = np.eye(4)
        m[:3, :3] = cv2.Rodrigues(rvec)[0]
        m[:3, 3] = tvec.ravel()
        camera.append(m)
        used_robot.append(pose)
    return opencv(setup, used_robot, camera), len(camera)


def robocal_trial(setup, trial_dir, images):
    """robocal on one trial: the images detected once (`robocal detect`),
    then `robocal handeye --detections` without --refine (the default) and
    with each other --refine mode. The closed forms come from the default run."""
    detections = os.path.join(trial_dir, "detections.json")
    subprocess.run([ROBOCAL, "detect", "--target", SPEC, "-o", detections, *images],
                   check=True, stderr=subprocess.DEVNULL)
    key = "gripper_from_camera" if setup == "eye-in-hand" else "base_from_camera"
    ours, used = {}, 0
    for mode in REFINE_MODES:
        out = os.path.join(trial_dir, f"robocal_{mode or 'default'}.json")
        subprocess.run([ROBOCAL, "handeye", "--setup", setup, "--poses",
                        os.path.join(trial_dir, "poses.txt"), "--pose-format", "matrix",
                        "--camera", os.path.join(trial_dir, "camera.json"),
                        "--detections", detections, *(["--refine", mode] if mode else []),
                        "--bootstrap", "0", "--lenient", "-o", out],
                       check=True, stderr=subprocess.DEVNULL)
        with open(out) as f:
            report = json.load(f)
        label = "robocal" if mode is None else f"robocal --refine {mode}"
        ours[label] = np.array(report[key]["matrix_row_major"])
        if mode is None:
            ours.update({"robocal " + m["method"]: np.array(m[key]["matrix_row_major"])
                         for m in report["methods"] if key in m})
            used = sum(1 for p in report.get("pairs", []) if p["used"])
    return ours, used


def main():
    trials, views = arg("--trials", 20), arg("--views", 12)
    if "--skip-render" not in sys.argv:
        subprocess.run(["cargo", "run", "--release", "--example", "handeye_charuco", "--",
                        OUT, "--trials", str(trials), "--views", str(views)],
                       cwd=ROOT, check=True)
    print(f"OpenCV {cv2.__version__}, numpy {np.__version__}, {platform.platform()}, "
          f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"{trials} trials per setup, {views} views each, {SPEC}")
    for setup in ("eye-in-hand", "eye-to-hand"):
        res, used = {}, {"robocal": [], "opencv": []}
        for trial_dir in sorted(glob.glob(os.path.join(OUT, setup, "trial_*")))[:trials]:
            with open(os.path.join(trial_dir, "truth.json")) as f:
                x = np.array(json.load(f)["x_true"])
            with open(os.path.join(trial_dir, "camera.json")) as f:
                cam = json.load(f)
            images = sorted(glob.glob(os.path.join(trial_dir, "view_*.png")))
            robot = read_matrices(os.path.join(trial_dir, "poses.txt"))
            theirs, n_cv = opencv_trial(setup, images, robot, cam)
            ours, n_rc = robocal_trial(setup, trial_dir, images)
            used["opencv"].append(n_cv)
            used["robocal"].append(n_rc)
            for name, est in theirs.items():
                res.setdefault("OpenCV " + name, []).append(errors(est, x))
            for name, est in ours.items():
                res.setdefault(name, []).append(errors(est, x))
        print(f"\n{setup}: X error vs truth over {len(used['robocal'])} trials; views used: "
              f"robocal {np.mean(used['robocal']):.2f}, OpenCV {np.mean(used['opencv']):.2f} "
              f"of {views} per trial")
        print("| method | rotation mean deg | rotation median deg | translation mean mm | "
              "translation median mm |")
        print("|---|---|---|---|---|")
        for name in sorted(res, key=lambda n: (not n.startswith("robocal"), n != "robocal", n)):
            e = np.array(res[name])
            e = e[np.isfinite(e).all(axis=1)]
            print(f"| {name} | {e[:, 0].mean():.4f} | {np.median(e[:, 0]):.4f} | "
                  f"{e[:, 1].mean():.3f} | {np.median(e[:, 1]):.3f} |")


if __name__ == "__main__":
    main()
