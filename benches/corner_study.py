#!/usr/bin/env python3
"""Corner study under camera effects (issue 42): robocal's chessboard
corners and OpenCV's against the renderer's exact truth, each camera effect
alone and a realistic combination, per image region; then the focal length
of calibrations from realistic renders.

Every set is `robocal render --camera <640x480 camera> --views N --seed 42
[effect flags]` (the same poses in every row: the seed fixes the scene), a
9x6 chessboard with 30 mm squares, blur sigma 0.7 px, grey-level noise 1
unless the row says otherwise. Detectors: `robocal detect`; OpenCV 4.14
findChessboardCorners + cornerSubPix (11x11, as its samples) and
findChessboardCornersSB. Errors are detected minus true pixel; the radial
component is along the truth's direction from the principal point (positive:
outward, what makes a calibrated focal length long). Regions by the truth's
distance r from the principal point over the half-diagonal: centre r < 0.3,
middle 0.3-0.6, outer r >= 0.6. bias = mean radial error; spread = RMS
distance.

--calib S: calibrations (brown, 5 coefficients) from 20 realistic views per
seed, seeds 1..S: robocal intrinsics on robocal's corners, OpenCV
calibrateCamera on its cornerSubPix corners; fx error against the truth
(600 px) and robocal's reported std.

Usage (crate root; runs in benches/.venv, see benches/opencv_venv.py):
  cargo build --release --bin robocal
  python3 benches/corner_study.py [--views 200] [--rows all|name,...] [--calib 5]
"""
import json
import os
import subprocess
import sys

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out", "corner_study")
ROBOCAL = os.path.join(ROOT, "target", "release", "robocal")
TARGET = "chessboard:9x6:30mm"
PATTERN = (9, 6)
# A 640x480 camera with barrel distortion (the demo camera's coefficients).
CAMERA = {"fx": 600.0, "fy": 600.0, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480,
          "distortion": {"k1": -0.18, "k2": 0.05, "p1": 0.0005, "p2": -0.0003, "k3": 0.0}}
CAMERA_FILE = {"image_size_px": [640, 480],
               "camera_matrix": [[600.0, 0.0, 319.5], [0.0, 600.0, 239.5], [0.0, 0.0, 1.0]],
               "model": "brown", "distortion": CAMERA["distortion"]}
ROWS = [
    ("ideal", []),
    ("gamma 2.2", ["--gamma", "2.2"]),
    ("lens blur", ["--defocus", "0.8", "--field-curvature", "1", "--astigmatism", "1.5", "--coma", "1.5"]),
    ("defocus + curvature", ["--defocus", "0.8", "--field-curvature", "1"]),
    ("coma 1.5", ["--coma", "1.5"]),
    ("astigmatism 1.5", ["--astigmatism", "1.5"]),
    ("motion 1.5 px", ["--motion", "1.5"]),
    ("bayer", ["--bayer"]),
    ("sensor 6000 e-", ["--full-well", "6000", "--noise", "0"]),
    ("jpeg 75", ["--jpeg", "75"]),
    ("paper 3 %", ["--paper-texture", "0.03"]),
    ("realistic", ["--effects", "realistic", "--noise", "0"]),
]


def run(cmd):
    subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def render(folder, views, seed, flags):
    os.makedirs(folder, exist_ok=True)
    cam = os.path.join(OUT, "camera.json")
    run([ROBOCAL, "render", "--out", folder, "--camera", cam, "--views", str(views), "--seed", str(seed),
         "--noise", "1", *flags])
    truth = json.load(open(os.path.join(folder, "truth.json")))
    files = [os.path.join(folder, v["image"]) for v in truth["views"]]
    return truth, files


def robocal_points(files, det_path):
    run([ROBOCAL, "detect", "--target", TARGET, "-o", det_path, *files])
    out = []
    for im in json.load(open(det_path))["images"]:
        d = im.get("detection")
        out.append({p["id"]: (p["x_px"], p["y_px"]) for p in d["points"]} if d else None)
    return out


def opencv_detectors():
    import cv2

    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)

    def classic(g):
        ok, c = cv2.findChessboardCorners(g, PATTERN)
        return cv2.cornerSubPix(g, c, (11, 11), (-1, -1), crit).reshape(-1, 2) if ok else None

    def sb(g):
        ok, c = cv2.findChessboardCornersSB(g, PATTERN)
        return c.reshape(-1, 2) if ok else None

    return {"cornerSubPix": classic, "findChessboardCornersSB": sb}


def match(found, truth_pts):
    """OpenCV's points to truth ids (its order may start at either end)."""
    import numpy as np

    ids = [p["id"] for p in truth_pts]
    t = np.array([[p["x_px"], p["y_px"]] for p in truth_pts])
    if len(found) != len(t):
        return None
    best = min((found, found[::-1]), key=lambda f: np.abs(f - t).sum())
    return {i: tuple(p) for i, p in zip(ids, best)}


def errors(found, view):
    """Rows (radius fraction, radial error, tangential error, distance)."""
    import numpy as np

    cx, cy = CAMERA["cx"], CAMERA["cy"]
    rmax = np.hypot(cx, cy)
    rows = []
    for p in view["points"]:
        if p["id"] not in found:
            continue
        fx, fy = found[p["id"]]
        ex, ey = fx - p["x_px"], fy - p["y_px"]
        dx, dy = p["x_px"] - cx, p["y_px"] - cy
        r = np.hypot(dx, dy)
        ux, uy = (dx / r, dy / r) if r > 1e-9 else (1.0, 0.0)
        rows.append((r / rmax, ex * ux + ey * uy, -ex * uy + ey * ux, np.hypot(ex, ey)))
    return rows


def summary(rows):
    import numpy as np

    a = np.array(rows)
    out = {}
    for name, lo, hi in [("all", 0, 9), ("centre", 0, 0.3), ("middle", 0.3, 0.6), ("outer", 0.6, 9)]:
        sel = a[(a[:, 0] >= lo) & (a[:, 0] < hi)]
        out[name] = (float(sel[:, 1].mean()), float(np.sqrt((sel[:, 3] ** 2).mean())), len(sel))
    return out


def study(views, names):
    import cv2

    print(f"corner study: {views} views per row, 640x480, {TARGET}, OpenCV {cv2.__version__}")
    print("bias = mean radial error px (+ outward), rms = RMS distance px; regions by r / half-diagonal\n")
    print(f"| effect | detector | found | bias all | bias centre | bias middle | bias outer | rms all | rms centre | rms outer |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    detectors = opencv_detectors()
    for name, flags in ROWS:
        if names != "all" and name not in names:
            continue
        folder = os.path.join(OUT, name.replace(" ", "_").replace("%", "pc"))
        truth, files = render(folder, views, 42, flags)
        per = {"robocal": robocal_points(files, os.path.join(folder, "robocal.json"))}
        for dname, fn in detectors.items():
            per[dname] = []
            for f, v in zip(files, truth["views"]):
                c = fn(cv2.imread(f, cv2.IMREAD_GRAYSCALE))
                per[dname].append(match(c, v["points"]) if c is not None else None)
        for dname, found in per.items():
            rows, n = [], 0
            for fpts, v in zip(found, truth["views"]):
                if fpts:
                    n += 1
                    rows += errors(fpts, v)
            s = summary(rows)
            print(f"| {name} | {dname} | {n}/{views} | {s['all'][0]:+.4f} | {s['centre'][0]:+.4f} | "
                  f"{s['middle'][0]:+.4f} | {s['outer'][0]:+.4f} | {s['all'][1]:.4f} | {s['centre'][1]:.4f} | "
                  f"{s['outer'][1]:.4f} |", flush=True)


def calibrations(seeds):
    import cv2
    import numpy as np

    print(f"\nfx from 20 realistic views (brown, 5 coefficients), truth fx = {CAMERA['fx']} px")
    print("| seed | robocal fx err px | robocal std px | err / std | OpenCV fx err px | OpenCV views |")
    print("|---|---|---|---|---|---|")
    obj = np.array([[i * 0.03, j * 0.03, 0.0] for j in range(6) for i in range(9)], np.float32)
    ratios, r_err, o_err = [], [], []
    for seed in range(1, seeds + 1):
        folder = os.path.join(OUT, f"calib_{seed}")
        truth, files = render(folder, 20, seed, ["--effects", "realistic", "--noise", "0"])
        det = os.path.join(folder, "robocal.json")
        run([ROBOCAL, "detect", "--target", TARGET, "-o", det, *files])
        rep = os.path.join(folder, "report.json")
        run([ROBOCAL, "intrinsics", "--detections", det, "--model", "brown", "-o", rep])
        report = json.load(open(rep))
        rfx, rstd = report["camera_matrix"][0][0] - CAMERA["fx"], report["std"]["fx"]
        objs, imgs = [], []
        classic = opencv_detectors()["cornerSubPix"]
        for f, v in zip(files, truth["views"]):
            c = classic(cv2.imread(f, cv2.IMREAD_GRAYSCALE))
            m = match(c, v["points"]) if c is not None else None
            if m:
                ids = sorted(m)
                objs.append(obj[ids].reshape(-1, 1, 3))
                imgs.append(np.array([m[i] for i in ids], np.float32).reshape(-1, 1, 2))
        _, k, _, _, _ = cv2.calibrateCamera(objs, imgs, (640, 480), None, None)
        ofx = k[0, 0] - CAMERA["fx"]
        ratios.append(abs(rfx) / rstd)
        r_err.append(abs(rfx))
        o_err.append(abs(ofx))
        print(f"| {seed} | {rfx:+.3f} | {rstd:.3f} | {rfx / rstd:+.2f} | {ofx:+.3f} | {len(objs)}/20 |", flush=True)
    print(f"| mean abs | {np.mean(r_err):.3f} | | {np.mean(ratios):.2f} | {np.mean(o_err):.3f} | |")


def main():
    ensure_venv()
    args = sys.argv[1:]
    views = int(args[args.index("--views") + 1]) if "--views" in args else 200
    names = args[args.index("--rows") + 1].split(",") if "--rows" in args else "all"
    calib = int(args[args.index("--calib") + 1]) if "--calib" in args else 0
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "camera.json"), "w") as f:
        json.dump(CAMERA_FILE, f)
    if names != ["none"]:
        study(views, names)
    if calib:
        calibrations(calib)


if __name__ == "__main__":
    main()
