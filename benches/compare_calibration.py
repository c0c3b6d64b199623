#!/usr/bin/env python3
"""Camera calibration: robocal vs OpenCV's calibrateCamera on the same
detections with the same model.

The detections are made once, by robocal (`robocal detect`), and written as
detections JSON; both solvers then read those very points:
  - opencv-left-9x6: the 13 OpenCV sample images left01..left14.jpg
    (640x480, chessboard 9x6, 30 mm squares), from ../shared/datasets;
  - render-N: `robocal render --views N --seed S` (1024x768, barrel
    distortion, grey-level noise 2), detected by robocal: 12, 20 and 40
    views of the 9x6 chessboard, and render-charuco-20: 20 views of a
    ChArUco 12x9 (11x8 inner corners, `charuco:12x9:30mm:22mm:DICT_5X5_100`).
For each set and model: OpenCV `cv2.calibrateCamera` (single-threaded,
`cv2.setNumThreads(1)`, default termination criteria except for the row
"rational converged" (run to its minimum); float32 points, as it requires, and
robocal gets the same float32-rounded values)
against `robocal intrinsics --detections FILE --model M [--fix ...]
--repeat R` (release build). Printed: the RMS of each and their
difference (target |diff| <= 1e-4 px); every parameter difference divided
by robocal's reported standard deviation (target <= 1); the median solve
time of each and the ratio OpenCV / robocal (target >= 2).

Timing: OpenCV's call is timed around `cv2.calibrateCamera` in Python, R
times, median. robocal's solve is timed inside the CLI (`--repeat R`: the
median wall time of `calibrate_input`, i.e. detections in memory to the
finished report, including its covariance, correlation and
projection-uncertainty grid; process start, file reading and JSON output
excluded), because the library core never reads a clock. On a shared,
loaded machine wall times swing by 2-3x, so CPU times are printed too:
OpenCV's per call (time.process_time), robocal's from the child process
(CPU of `--repeat R+1` minus CPU of a single solve, over R).

Usage (crate root; runs in benches/.venv, see benches/opencv_venv.py):
  cargo build --release --bin robocal
  python3 benches/compare_calibration.py [--repeat 21] [--quick] [--robocal PATH]
"""
import argparse
import glob
import json
import os
import platform
import re
import resource
import subprocess
import sys
import tempfile
import time

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATASETS = [os.path.join(ROOT, "..", "shared", "datasets"), "/work/shared/datasets"]

# OpenCV name -> index in its distortion vector.
OPENCV_COEFFS = ["k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"]
# name: (robocal --model, robocal extra flags, OpenCV flags (names), coefficients compared)
MODELS = {
    "brown5": ("brown", [], [], ["k1", "k2", "p1", "p2", "k3"]),
    "brown4 (fix k3)": ("brown", ["--fix", "k3"], ["CALIB_FIX_K3"], ["k1", "k2", "p1", "p2"]),
    "brown5 fx=fy": ("brown", ["--aspect-ratio", "1"], ["CALIB_FIX_ASPECT_RATIO"], ["k1", "k2", "p1", "p2", "k3"]),
    "radial k1 k2": ("brown", ["--fix", "p1", "--fix", "p2", "--fix", "k3"],
                     ["CALIB_ZERO_TANGENT_DIST", "CALIB_FIX_K3"], ["k1", "k2"]),
    "rational k1-k6": ("rational", ["--fix", "s1", "--fix", "s2", "--fix", "s3", "--fix", "s4"],
                       ["CALIB_RATIONAL_MODEL"], ["k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"]),
    # The same, with OpenCV run to its minimum as robocal is (its default
    # criteria stop after 30 iterations, short of the minimum in this
    # valley): the like-for-like time of one converged solve.
    "rational converged": ("rational", ["--fix", "s1", "--fix", "s2", "--fix", "s3", "--fix", "s4"],
                           ["CALIB_RATIONAL_MODEL"], ["k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"]),
}
# OpenCV termination criteria per model (default: OpenCV's own, 30 iterations
# or a relative change below DBL_EPSILON).
CONVERGED_ITERATIONS = 1000
CRITERIA = {"rational converged": CONVERGED_ITERATIONS}
QUICK_MODELS = ["brown5", "brown5 fx=fy"]
CHESSBOARD = "chessboard:9x6:30mm"
# 11 x 8 inner corners (88 points a view), 1024x768 renders as the chessboard's.
CHARUCO = "charuco:12x9:30mm:22mm:DICT_5X5_100"


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{out.stderr}")
    return out


def dataset_dir(name):
    for d in DATASETS:
        p = os.path.join(d, name)
        if os.path.isdir(p):
            return p
    return None


def detect(robocal, target, images, out):
    run([robocal, "detect", "--target", target, "--threads", "1", "-o", out, *images])
    return out


def board_points(target):
    """Object points by id for a chessboard target object (robocal's order:
    id = row * cols + col at (col, row) * square, z = 0)."""
    import numpy as np

    if target.get("kind") == "charuco":
        # Inner corners, id = row * (squares_x - 1) + col at ((col + 1), (row + 1)) * square.
        cols, rows, sq = target["squares_x"] - 1, target["squares_y"] - 1, target["square_m"]
        return np.array([[(i + 1) * sq, (j + 1) * sq, 0.0] for j in range(rows) for i in range(cols)],
                        np.float64)
    cols, rows, sq = target["cols"], target["rows"], target["square_m"]
    return np.array([[i * sq, j * sq, 0.0] for j in range(rows) for i in range(cols)], np.float64)


def opencv_inputs(detections):
    import numpy as np

    obj, img, size = [], [], None
    for image in detections["images"]:
        d = image.get("detection")
        if not d:
            continue
        board = board_points(d["target"])
        ids = [p["id"] for p in d["points"]]
        obj.append(board[ids].astype(np.float32).reshape(-1, 1, 3))
        img.append(np.array([[p["x_px"], p["y_px"]] for p in d["points"]], np.float32).reshape(-1, 1, 2))
        size = tuple(d["image_size_px"])
    return obj, img, size


def opencv_calibrate(obj, img, size, flag_names, repeat, max_iterations=None):
    import cv2
    import numpy as np

    extra = {}
    if max_iterations:
        extra["criteria"] = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, max_iterations, sys.float_info.epsilon)

    flags = 0
    for f in flag_names:
        flags |= getattr(cv2, f)
    times, cpu, result = [], [], None
    for _ in range(repeat):
        k0 = np.eye(3)  # aspectRatio 1 with CALIB_FIX_ASPECT_RATIO, as OpenCV's sample
        t0, c0 = time.perf_counter(), time.process_time()
        result = cv2.calibrateCamera(obj, img, size, k0, None, flags=flags, **extra)
        times.append((time.perf_counter() - t0) * 1e3)
        cpu.append((time.process_time() - c0) * 1e3)
    rms, k, dist = result[0], result[1], result[2].reshape(-1)
    params = {"fx": k[0, 0], "fy": k[1, 1], "cx": k[0, 2], "cy": k[1, 2]}
    for i, name in enumerate(OPENCV_COEFFS[: len(dist)]):
        params[name] = dist[i]
    return rms, params, median(times), median(cpu)


def median(values):
    return sorted(values)[len(values) // 2]


def child_cpu_ms(cmd):
    """Run cmd; its CPU time (user + system), ms, and its standard error."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    stderr = run(cmd).stderr
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    used = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return used * 1e3, stderr


def robocal_calibrate(robocal, detections_path, model, extra, repeat, out):
    base = [robocal, "intrinsics", "--detections", detections_path, "--model", model, *extra, "-o", out]
    cmd = base + ["--repeat", str(repeat + 1)]
    # CPU time of one solve: the process with repeat + 1 solves minus the
    # process with one (start-up, reading and writing cancel out).
    cpu_one, _ = child_cpu_ms(base)
    cpu_many, stderr = child_cpu_ms(cmd)
    m = re.search(r"solve time median ([0-9.]+) ms", stderr)
    if not m:
        sys.exit(f"no solve time in: {stderr}")
    with open(out) as f:
        report = json.load(f)
    k = report["camera_matrix"]
    params = {"fx": k[0][0], "fy": k[1][1], "cx": k[0][2], "cy": k[1][2], **report["distortion"]}
    cpu = (cpu_many - cpu_one) / repeat
    return report["rms_px"], params, report["std"], float(m.group(1)), cpu, " ".join(cmd)


def as_float32(detections_path):
    """The detections with every pixel rounded to float32 (calibrateCamera
    takes float32 points only), written beside the input: both solvers then
    see bit-identical points."""
    import numpy as np

    with open(detections_path) as f:
        detections = json.load(f)
    for image in detections["images"]:
        for p in (image.get("detection") or {}).get("points", []):
            p["x_px"] = float(np.float32(p["x_px"]))
            p["y_px"] = float(np.float32(p["y_px"]))
    out = detections_path.replace(".json", "-f32.json")
    with open(out, "w") as f:
        json.dump(detections, f)
    return detections, out


def compare(name, robocal, detections_path, models, repeat):
    detections, detections_path = as_float32(detections_path)
    obj, img, size = opencv_inputs(detections)
    n_points = sum(len(o) for o in obj)
    print(f"\n## {name}: {len(obj)} views, {n_points} points, {size[0]}x{size[1]}")
    print(f"{'model':16s} {'rms robocal':>12s} {'rms opencv':>11s} {'diff px':>9s} "
          f"{'max |d|/std':>11s} {'(param)':>8s} {'robocal ms':>10s} {'opencv ms':>9s} {'speed-up':>8s} "
          f"{'cpu robocal':>11s} {'cpu opencv':>10s} {'cpu speed-up':>12s}")
    rows = []
    for label in models:
        model, extra, flags, coeffs = MODELS[label]
        with tempfile.NamedTemporaryFile(suffix=".json") as out:
            r_rms, r_params, r_std, r_ms, r_cpu, cmd = robocal_calibrate(robocal, detections_path, model, extra,
                                                                  repeat, out.name)
        o_rms, o_params, o_ms, o_cpu = opencv_calibrate(obj, img, size, flags, repeat, CRITERIA.get(label))
        ratios = {}
        for p in ["fx", "fy", "cx", "cy", *coeffs]:
            std = r_std.get(p, 0.0)
            diff = r_params[p] - o_params[p]
            if std > 0:
                ratios[p] = abs(diff) / std
            elif abs(diff) > 1e-9 * max(1.0, abs(o_params[p])):
                ratios[p] = float("inf")  # held in robocal but moved in OpenCV
        worst = max(ratios, key=ratios.get)
        print(f"{label:16s} {r_rms:12.6f} {o_rms:11.6f} {r_rms - o_rms:+9.1e} {ratios[worst]:11.4f} "
              f"{worst:>8s} {r_ms:10.3f} {o_ms:9.3f} {o_ms / r_ms:7.1f}x "
              f"{r_cpu:11.3f} {o_cpu:10.3f} {o_cpu / r_cpu:11.1f}x")
        rows.append({"set": name, "model": label, "rms_robocal_px": r_rms, "rms_opencv_px": o_rms,
                     "diff_over_std": ratios, "robocal_ms": r_ms, "opencv_ms": o_ms, "robocal_cpu_ms": r_cpu, "opencv_cpu_ms": o_cpu,
                     "command": cmd})
    return rows


def main():
    ensure_venv()
    import cv2

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=21, help="timed solves per case (median)")
    ap.add_argument("--quick", action="store_true", help="two models, one rendered set")
    ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
    ap.add_argument("--json", help="also write every row (with the per-parameter ratios) here")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    robocal = os.path.abspath(args.robocal)
    if not os.path.exists(robocal):
        sys.exit(f"{robocal} not found: run `cargo build --release --bin robocal` first")
    print(f"OpenCV {cv2.__version__} calibrateCamera, single-threaded; robocal {robocal} "
          f"(solve timed in-process, --repeat {args.repeat}); {platform.machine()}, {os.cpu_count()} cores")
    models = QUICK_MODELS if args.quick else list(MODELS)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        left = dataset_dir("opencv-left-right-9x6")
        if left:
            images = sorted(glob.glob(os.path.join(left, "left*.jpg")))
            path = detect(robocal, "chessboard:9x6:30mm", images, os.path.join(tmp, "left.json"))
            rows += compare("opencv-left-9x6 (robocal detections)", robocal, path, models, args.repeat)
        else:
            print("\n(opencv-left-right-9x6 not found: skipped)")
        sets = [(12, 1, CHESSBOARD)] if args.quick else [(12, 1, CHESSBOARD), (20, 3, CHESSBOARD),
                                                           (20, 5, CHARUCO), (40, 7, CHESSBOARD)]
        for views, seed, target in sets:
            kind = "charuco-" if target == CHARUCO else ""
            out = os.path.join(tmp, f"render{kind}{views}")
            run([robocal, "render", "--out", out, "--views", str(views), "--seed", str(seed), "--target", target])
            images = sorted(glob.glob(os.path.join(out, "view_*.png")))
            path = detect(robocal, target, images, os.path.join(tmp, f"render{kind}{views}.json"))
            rows += compare(f"render-{kind}{views} (seed {seed}, robocal detections)", robocal, path, models,
                            args.repeat)
    print("\ndiff px = rms robocal - rms opencv; max |d|/std = largest |robocal - opencv| over "
          "fx fy cx cy and the model's coefficients, in robocal's reported std (param: which); "
          "speed-up = opencv ms / robocal ms (median wall times of one solve); cpu = CPU time of one "
          "solve (OpenCV: median of process_time per call; robocal: CPU time of the process with "
          "repeat + 1 solves minus the process with 1, over repeat), less sensitive to a loaded machine")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
