#!/usr/bin/env python3
"""Hand-eye accuracy: robocal vs OpenCV on the same noisy synthetic data.

Data are generated the way OpenCV's test_calibration_hand_eye.cpp does
(10 poses; X rotation 10-50 deg; robot poses 5-45 deg; noise: camera
rotation vector 0.002 rad and translation 5 mm, robot 0.001 rad and 1 mm per
component), for eye-in-hand and eye-to-hand. Every trial is given to
cv2.calibrateHandEye (5 methods), cv2.calibrateRobotWorldHandEye (Shah, Li)
and `robocal handeye --camera-poses` (all 8 methods, via its JSON report).
Printed: per method, the median and 90th percentile of the rotation error
(deg) and translation error (mm) of the camera transform against the truth.

Usage (from the crate root, after `cargo build`):
  python3 benches/compare_handeye.py [--trials 100] [--seed 7] [--robocal target/debug/robocal]
It runs in benches/.venv (opencv-python-headless==4.14.0.94, pinned in
benches/opencv_venv.py; created on first run).
"""
import argparse
import json
import os
import platform
import subprocess
import tempfile

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402  (after the venv switch)
import numpy as np  # noqa: E402

cv2.setNumThreads(1)

OPENCV_AXXB = {
    "tsai-lenz": cv2.CALIB_HAND_EYE_TSAI,
    "park-martin": cv2.CALIB_HAND_EYE_PARK,
    "horaud": cv2.CALIB_HAND_EYE_HORAUD,
    "andreff": cv2.CALIB_HAND_EYE_ANDREFF,
    "daniilidis": cv2.CALIB_HAND_EYE_DANIILIDIS,
}
OPENCV_AXZB = {
    "shah": cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH,
    "li": cv2.CALIB_ROBOT_WORLD_HAND_EYE_LI,
}
ROBOCAL_METHODS = ["tsai-lenz", "park-martin", "horaud", "andreff", "daniilidis",
                   "chou-kamel", "shah", "li"]


def pose(rng, theta_deg, t_range):
    axis = rng.uniform(-1.0, 1.0, 3)
    axis /= np.linalg.norm(axis)
    theta = np.radians(rng.uniform(*theta_deg)) * rng.choice([-1.0, 1.0])
    t = rng.uniform(*t_range, 3) * rng.choice([-1.0, 1.0], 3)
    m = np.eye(4)
    m[:3, :3] = cv2.Rodrigues(axis * theta)[0]
    m[:3, 3] = t
    return m


def perturb(rng, m, sigma_r, sigma_t):
    out = m.copy()
    rvec = cv2.Rodrigues(m[:3, :3])[0].ravel() + rng.normal(0.0, sigma_r, 3)
    out[:3, :3] = cv2.Rodrigues(rvec)[0]
    out[:3, 3] += rng.normal(0.0, sigma_t, 3)
    return out


def scene(rng, setup, views=10):
    near, far = (0.05, 0.5), (0.5, 3.5)
    if setup == "eye-in-hand":
        x, y = pose(rng, (10, 50), near), pose(rng, (5, 85), far)
    else:
        x, y = pose(rng, (10, 50), far), pose(rng, (5, 85), near)
    robot, camera = [], []
    for _ in range(views):
        bg = pose(rng, (5, 45), (0.5, 1.5))
        if setup == "eye-in-hand":
            ct = np.linalg.inv(x) @ np.linalg.inv(bg) @ y
            bg_noisy = perturb(rng, bg, 0.001, 0.001)
        else:
            ct = np.linalg.inv(x) @ bg @ y
            bg_noisy = np.linalg.inv(perturb(rng, np.linalg.inv(bg), 0.001, 0.001))
        camera.append(perturb(rng, ct, 0.002, 0.005))
        robot.append(bg_noisy)
    return x, robot, camera


def errors(est, truth):
    d = np.linalg.inv(truth) @ est
    angle = np.degrees(np.linalg.norm(cv2.Rodrigues(d[:3, :3])[0]))
    return angle, 1e3 * np.linalg.norm(est[:3, 3] - truth[:3, 3])


def homogeneous(r, t):
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = np.ravel(t)
    return m


def opencv(setup, robot, camera):
    out = {}
    # calibrateHandEye takes gripper2base (eye-in-hand) or base2gripper (eye-to-hand).
    handed = robot if setup == "eye-in-hand" else [np.linalg.inv(m) for m in robot]
    for name, flag in OPENCV_AXXB.items():
        r, t = cv2.calibrateHandEye([m[:3, :3] for m in handed], [m[:3, 3] for m in handed],
                                    [m[:3, :3] for m in camera], [m[:3, 3] for m in camera],
                                    method=flag)
        out[name] = homogeneous(r, t)
    # calibrateRobotWorldHandEye: cTw = cTg gTb bTw. Eye-in-hand: world = target,
    # g = gripper, b = base (pass gripper_from_base). Eye-to-hand: the roles of
    # base and gripper swap (pass base_from_gripper). X = inverse(cTg).
    rw = [np.linalg.inv(m) for m in robot] if setup == "eye-in-hand" else robot
    for name, flag in OPENCV_AXZB.items():
        _, _, r, t = cv2.calibrateRobotWorldHandEye(
            [m[:3, :3] for m in camera], [m[:3, 3] for m in camera],
            [m[:3, :3] for m in rw], [m[:3, 3] for m in rw], method=flag)
        out[name] = np.linalg.inv(homogeneous(r, t))
    return out


def robocal(binary, setup, robot, camera, tmp):
    files = []
    for name, poses in (("robot.txt", robot), ("camera.txt", camera)):
        path = os.path.join(tmp, name)
        with open(path, "w") as f:
            for m in poses:
                f.write(" ".join(f"{v:.17g}" for v in m.ravel()) + "\n")
        files.append(path)
    out = os.path.join(tmp, "handeye.json")
    subprocess.run([binary, "handeye", "--setup", setup, "--poses", files[0],
                    "--camera-poses", files[1], "--bootstrap", "0", "--lenient", "-o", out],
                   check=True, stderr=subprocess.DEVNULL)
    with open(out) as f:
        report = json.load(f)
    key = "gripper_from_camera" if setup == "eye-in-hand" else "base_from_camera"
    ours = {m["method"]: np.array(m[key]["matrix_row_major"]) for m in report["methods"]
            if key in m}
    # The primary transform is the report's own (the pose refinement's since
    # issue 19, method 'refined from <closed form>').
    ours[report["method"]] = np.array(report[key]["matrix_row_major"])
    return ours, report["method"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=100)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--robocal", default="target/debug/robocal")
    a = ap.parse_args()
    print(f"OpenCV {cv2.__version__}, numpy {np.__version__}, {platform.platform()}, "
          f"{platform.processor() or platform.machine()}; {a.trials} trials per setup, seed {a.seed}")
    for setup in ("eye-in-hand", "eye-to-hand"):
        rng = np.random.default_rng(a.seed)
        res = {}
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(a.trials):
                x, robot, camera = scene(rng, setup)
                for name, est in opencv(setup, robot, camera).items():
                    res.setdefault(("opencv", name), []).append(errors(est, x))
                ours, primary = robocal(a.robocal, setup, robot, camera, tmp)
                for name, est in ours.items():
                    res.setdefault(("robocal", name), []).append(errors(est, x))
                res.setdefault(("robocal", "primary (" + "auto" + ")"), []).append(
                    errors(ours[primary], x))
        print(f"\n{setup}: error of the camera transform vs truth")
        print(f"{'method':<14}{'impl':<9}{'rot med deg':>12}{'rot p90':>10}"
              f"{'t med mm':>10}{'t p90 mm':>10}{'NaN':>5}")
        for method in ROBOCAL_METHODS + ["primary (auto)"]:
            for impl in ("opencv", "robocal"):
                e = res.get((impl, method))
                if not e:
                    continue
                e = np.array(e)
                nan = int(np.sum(~np.isfinite(e).all(axis=1)))
                e = e[np.isfinite(e).all(axis=1)]
                print(f"{method:<14}{impl:<9}{np.median(e[:, 0]):12.4f}{np.percentile(e[:, 0], 90):10.4f}"
                      f"{np.median(e[:, 1]):10.2f}{np.percentile(e[:, 1], 90):10.2f}{nan:5d}")


if __name__ == "__main__":
    main()
