#!/usr/bin/env python3
"""Intrinsics from real sets against their published results (issue 42):
robocal and OpenCV side by side, each from its own corners, against the
reference that came with the set (../shared/datasets/*/SOURCE.md).

Sets (each skipped with a message when its folder is absent):
  - opencv-left-right-9x6: the 13 left and 13 right JPEGs against Bouguet's
    toolbox calibrations of example 5 (14 views with pair 10, which OpenCV
    does not ship; his default model: k1 k2 p1 p2, k3 held at 0, no skew),
    and the 13 left ones against OpenCV's left_intrinsics.yml (the sample's
    flags = 2: fx = fy, 5 coefficients). No std is published for either.
  - zhang1998: Zhang's alpha beta gamma u0 v0 k1 k2 (skew free, radial
    k1 k2), from his own corners (data1..5.txt) and from his five photos.
    robocal takes his corners through its own square-grid detection of the
    photos (each of his corners replaces the detected corner nearest to it,
    so the ids and the board frame are robocal's); OpenCV takes them with
    Model.txt. OpenCV has no skew and finds no board in the photos.
  - opencv-calib1-dat: Bouguet's result in calib1.dat (k1 k2 p1 p2, 7 views
    of point data, no images), with the uncertainty block of the file as
    it stands (the toolbox's errors; the script prints their ratio to
    OpenCV's std, 1.50).
  - caliscope-4cam-charuco-video: caliscope's camera_array.toml (brown5,
    fx and fy free) against every frame of each camera's video (inverted
    ChArUco 4x5, 54 mm squares) and camera 0's chessboard_intrinsic frames
    (fx fy cx cy only: four near-frontal views).
    caliscope calibrated from its own intrinsic recording, not shipped.
  - rwhe-calib-cs-synthetic-1: no published intrinsics (SOURCE.md), skipped.

robocal: `robocal intrinsics --target SPEC IMAGES` (or `--detections` for
point data) with the reference's model; OpenCV: findChessboardCorners +
cornerSubPix with the reference's window (Bouguet's wintx = 7, i.e. 15x15;
the calibration sample's winSize 11, i.e. 23x23, for left_intrinsics.yml
and caliscope's chessboard frames) or the ChArUco detector, then
calibrateCameraExtended with the matching flags. Rows "same, robocal's
solver on OpenCV's corners" feed OpenCV's corners to `robocal intrinsics
--detections`: they separate the corners from the solver. For the Bouguet
sets the script also prints how robocal's corners sit against OpenCV's
(median distance, mean offset away from the view's corner centroid).

Columns: reference (+- its std when published), robocal (+- its reported
std), OpenCV (+- its std), then robocal - reference and OpenCV - reference
in the reference's std (when published) and in robocal's std. "off" marks a
parameter where robocal is beyond 2 std of the reference while OpenCV is
within (the reference's std when published, else robocal's); a report at
severity error (robocal's "these parameters are not a calibration") is
marked as such.

Usage (crate root; about 2 minutes, most of it caliscope's 444 frames):
  cargo build --release --bin robocal
  python3 benches/real_sets.py [--robocal PATH] [--keep DIR] [--sets left_right,zhang,calib1,caliscope,rwhe]
"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATASETS = [os.path.join(ROOT, "..", "shared", "datasets"), "/work/shared/datasets"]
CHARUCO = "charuco:4x5:54mm:40.5mm:DICT_4X4_1000"


def opencv():
    """cv2 4.14 when this python has it, else benches/.venv's."""
    try:
        import cv2

        if cv2.__version__.startswith("4.14"):
            return cv2
    except ImportError:
        pass
    from opencv_venv import ensure_venv

    ensure_venv()
    import cv2

    return cv2


cv2 = opencv()
import numpy as np  # noqa: E402  (after the venv is settled)

cv2.setNumThreads(1)


def dataset_dir(name):
    for d in DATASETS:
        p = os.path.join(d, name)
        if os.path.isdir(p):
            return os.path.abspath(p)
    return None


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{out.stderr}")
    return out


# ---------------------------------------------------------------- robocal


def robocal_intrinsics(robocal, source, flags, out):
    """source: ["--target", SPEC, images...] or ["--detections", FILE]."""
    cmd = [robocal, "intrinsics", *source, "--threads", "2", *flags, "-o", out]
    stderr = run(cmd).stderr
    with open(out) as f:
        r = json.load(f)
    k, std = r["camera_matrix"], r["std"]
    p = {"fx": k[0][0], "fy": k[1][1], "cx": k[0][2], "cy": k[1][2], "skew": k[0][1], **r["distortion"]}
    skipped = [line.strip() for line in stderr.splitlines() if "not found" in line or "skipp" in line]
    return {"p": p, "std": std, "rms": r["rms_px"], "views": len(r["views"]), "skipped": skipped,
            "severity": r["severity"]}


def robocal_on_corners(robocal, img, size, cols, rows, flags, out):
    """robocal's solver on OpenCV's chessboard corners (OpenCV's index as
    the id: the same row-major grid as robocal's chessboard)."""
    det = {"images": [{"file": f"view{k + 1}", "detection": {
        "image_size_px": list(size), "polarity": "dark_on_light",
        "target": {"kind": "chessboard", "cols": cols, "rows": rows, "square_m": 0.03},
        "points": [{"id": i, "x_px": float(q[0][0]), "y_px": float(q[0][1])} for i, q in enumerate(c)]}}
        for k, c in enumerate(img)]}
    path = out.replace(".json", "-detections.json")
    with open(path, "w") as f:
        json.dump(det, f)
    return robocal_intrinsics(robocal, ["--detections", path], flags, out)


def robocal_detect(robocal, spec, images, out):
    run([robocal, "detect", "--target", spec, "--threads", "2", "-o", out, *images])
    with open(out) as f:
        return json.load(f)


# ---------------------------------------------------------------- OpenCV

COEFFS = ["k1", "k2", "p1", "p2", "k3"]


def cv_calibrate(obj, img, size, flags, fx_eq_fy=False):
    k0 = np.eye(3) if fx_eq_fy else None
    rms, k, d, _, _, std_in, _, _ = cv2.calibrateCameraExtended(obj, img, size, k0, None, flags=flags)
    d, s = d.reshape(-1), std_in.reshape(-1)
    p = {"fx": k[0, 0], "fy": k[1, 1], "cx": k[0, 2], "cy": k[1, 2]}
    std = {"fx": s[0], "fy": s[1], "cx": s[2], "cy": s[3]}
    for i, name in enumerate(COEFFS):
        p[name], std[name] = d[i], s[4 + i]
    return {"p": p, "std": std, "rms": rms, "views": len(obj)}


def cv_chessboard(images, cols, rows, half_window):
    obj, img, size, found = [], [], None, []
    grid = np.array([[i, j, 0] for j in range(rows) for i in range(cols)], np.float32)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.0001)
    for path in images:
        gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
        size = gray.shape[::-1]
        ok, c = cv2.findChessboardCorners(gray, (cols, rows), None)
        if not ok:
            continue
        c = cv2.cornerSubPix(gray, c, (half_window, half_window), (-1, -1), crit)
        obj.append(grid.reshape(-1, 1, 3))
        img.append(c)
        found.append(os.path.basename(path))
    return obj, img, size, found


def cv_charuco(images):
    board = cv2.aruco.CharucoBoard((4, 5), 0.054, 0.0405, cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_1000))
    detector = cv2.aruco.CharucoDetector(board)
    obj, img, size = [], [], None
    for path in images:
        gray = 255 - cv2.imread(path, cv2.IMREAD_GRAYSCALE)  # printed inverted
        size = gray.shape[::-1]
        corners, ids, _, _ = detector.detectBoard(gray)
        if ids is None or len(ids) < 6:
            continue
        o, i = board.matchImagePoints(corners, ids)
        obj.append(o.astype(np.float32))
        img.append(i.astype(np.float32))
    return obj, img, size


# ---------------------------------------------------------------- table

ROWS = []


def add_rows(name, params, ref, ref_std, rc, cv):
    for q in params:
        ROWS.append((name, q, ref[q], ref_std.get(q) if ref_std else None,
                     rc["p"].get(q), rc["std"].get(q),
                     cv["p"].get(q) if cv else None, cv["std"].get(q) if cv else None,
                     rc.get("severity")))


def fmt(v, std=None):
    if v is None:
        return "-"
    digits = 5 if abs(v) < 10 else 3
    s = f"{v:.{digits}f}"
    return s + (f" ± {std:.{digits}f}" if std else "")


def ratio(d, s):
    return f"{d / s:+.2f}" if d is not None and s else "-"


def print_table():
    print("\n| set | parameter | reference | robocal | OpenCV | robocal−ref / ref std | robocal−ref / robocal std "
          "| OpenCV−ref / ref std | OpenCV−ref / robocal std | |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, q, ref, rs, rv, rcs, cvv, cvs, severity in ROWS:
        drc = rv - ref if rv is not None else None
        dcv = cvv - ref if cvv is not None else None
        unit = rs or rcs
        mark = ""
        if unit and drc is not None and dcv is not None:
            if abs(drc / unit) > 2 and abs(dcv / unit) <= 2:
                mark = "off"
        if severity == "error":
            mark = "robocal: error (no calibration)"
        print(f"| {name} | {q} | {fmt(ref, rs)} | {fmt(rv, rcs)} | {fmt(cvv, cvs)} | {ratio(drc, rs)} | "
              f"{ratio(drc, rcs)} | {ratio(dcv, rs)} | {ratio(dcv, rcs)} | {mark} |")


def note(text):
    print(f"- {text}")


# ---------------------------------------------------------------- sets


def left_right(robocal, tmp):
    d = dataset_dir("opencv-left-right-9x6")
    if not d:
        return note("skipped opencv-left-right-9x6: folder not found in ../shared/datasets")
    bouguet = {
        "left": ({"fx": 533.00371, "fy": 533.15260, "cx": 341.58612, "cy": 234.25940}),
        "right": ({"fx": 536.98262, "fy": 536.56938, "cx": 326.47209, "cy": 249.33257}),
    }
    for side, ref in bouguet.items():
        images = sorted(glob.glob(os.path.join(d, f"{side}[0-9][0-9].jpg")))
        rc = robocal_intrinsics(robocal, ["--target", "chessboard:9x6:30mm", *images], ["--fix", "k3"],
                                os.path.join(tmp, f"{side}.json"))
        # Bouguet's corner window: wintx = winty = 7 (SOURCE.md).
        obj, img, size, found = cv_chessboard(images, 9, 6, 7)
        cv = cv_calibrate([o * 30 for o in obj], img, size, cv2.CALIB_FIX_K3)
        name = f"OpenCV {side} 13 JPEGs vs Bouguet ex. 5 (k3 = 0)"
        add_rows(name, ["fx", "fy", "cx", "cy"], ref, None, rc, cv)
        note(f"{name}: robocal {rc['views']} views rms {rc['rms']:.4f} px, OpenCV {cv['views']} views "
             f"rms {cv['rms']:.4f} px (cornerSubPix 15x15); Bouguet had 14 views (pair 10 not shipped)")
        det = robocal_detect(robocal, "chessboard:9x6:30mm", images, os.path.join(tmp, f"{side}-detect.json"))
        corner_offsets(side, det, found, img, size)
        on = robocal_on_corners(robocal, img, size, 9, 6, ["--fix", "k3"], os.path.join(tmp, f"{side}-cv.json"))
        add_rows(f"same, robocal's solver on OpenCV's 15x15 {side} corners", ["fx", "fy", "cx", "cy"], ref, None,
                 on, cv)
    yml = cv2.FileStorage(os.path.join(d, "left_intrinsics.yml"), cv2.FILE_STORAGE_READ)
    k, dist = yml.getNode("camera_matrix").mat(), yml.getNode("distortion_coefficients").mat().reshape(-1)
    ref = {"fx": k[0, 0], "cx": k[0, 2], "cy": k[1, 2], **dict(zip(COEFFS, dist))}
    images = sorted(glob.glob(os.path.join(d, "left[0-9][0-9].jpg")))
    rc = robocal_intrinsics(robocal, ["--target", "chessboard:9x6:25mm", *images], ["--aspect-ratio", "1"],
                            os.path.join(tmp, "left-yml.json"))
    # The calibration sample's corner window: winSize 11 (23x23).
    obj, img, size, _ = cv_chessboard(images, 9, 6, 11)
    cv = cv_calibrate([o * 25 for o in obj], img, size, cv2.CALIB_FIX_ASPECT_RATIO, fx_eq_fy=True)
    name = "OpenCV left vs left_intrinsics.yml (fx = fy)"
    params = ["fx", "cx", "cy", "k1", "k2", "p1", "p2", "k3"]
    add_rows(name, params, ref, None, rc, cv)
    note(f"{name}: robocal rms {rc['rms']:.4f} px, OpenCV rms {cv['rms']:.4f} px (cornerSubPix 23x23), "
         f"file {yml.getNode('avg_reprojection_error').real():.4f} px")
    rc = robocal_on_corners(robocal, img, size, 9, 6, ["--aspect-ratio", "1"], os.path.join(tmp, "left-cv.json"))
    name = "same, robocal's solver on OpenCV's 23x23 corners"
    add_rows(name, params, ref, None, rc, cv)
    note(f"{name}: robocal rms {rc['rms']:.4f} px")


def corner_offsets(side, det, found, cv_img, size):
    """robocal's corners against OpenCV's: median distance, the mean
    offset away from each view's corner centroid (positive = robocal's
    board looks larger) and away from the image centre per radius band
    (a field-dependent offset moves the focal length and k1)."""
    by_name = {os.path.basename(e["file"]): e.get("detection") for e in det["images"]}
    centre_px = (np.array(size, np.float64) - 1) / 2
    dist, outward, radial = [], [], []
    for name, c in zip(found, cv_img):
        d = by_name.get(name)
        if not d:
            continue
        rc = np.array([[p["x_px"], p["y_px"]] for p in d["points"]])
        cv = c.reshape(-1, 2).astype(np.float64)
        centroid = cv.mean(0)
        for q in cv:
            off = rc[np.argmin(((rc - q) ** 2).sum(1))] - q
            dist.append(np.hypot(*off))
            u = (q - centroid) / max(np.hypot(*(q - centroid)), 1e-9)
            outward.append(float(off @ u))
            r = np.hypot(*(q - centre_px))
            radial.append((r, float(off @ (q - centre_px)) / max(r, 1e-9)))
    radial = np.array(radial)
    bands = []
    for lo, hi in [(0, 100), (100, 200), (200, 300), (300, 800)]:
        m = (radial[:, 0] >= lo) & (radial[:, 0] < hi)
        if m.any():
            bands.append(f"{lo}-{hi} px {radial[m, 1].mean():+.3f} (n {m.sum()})")
    note(f"{side} corners, robocal vs OpenCV 15x15 over {len(dist)}: median distance {np.median(dist):.3f} px, "
         f"mean outward offset {np.mean(outward):+.4f} px (std of mean {np.std(outward) / np.sqrt(len(outward)):.4f}); "
         f"away from the image centre by radius: {', '.join(bands)}")


def numbers(path):
    with open(path) as f:
        return [float(v) for v in f.read().split()]


def zhang(robocal, tmp):
    d = dataset_dir("zhang1998")
    if not d:
        return note("skipped zhang1998: folder not found in ../shared/datasets")
    v = numbers(os.path.join(d, "completecalibration.txt"))
    ref = {"fx": v[0], "skew": v[1], "fy": v[2], "cx": v[3], "cy": v[4], "k1": v[5], "k2": v[6]}
    params = ["fx", "fy", "skew", "cx", "cy", "k1", "k2"]
    flags = ["--free-skew", "--fix", "p1", "--fix", "p2", "--fix", "k3"]
    cv_flags = cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K3
    spec = "squares:8x8:12.7mm:22.5778mm"
    images = [os.path.join(d, f"image{k}.gif") for k in range(1, 6)]
    model = np.array(numbers(os.path.join(d, "Model.txt"))).reshape(-1, 2)
    data = [np.array(numbers(os.path.join(d, f"data{k}.txt"))).reshape(-1, 2) for k in range(1, 6)]

    # His corners, in robocal's ids: each replaces the nearest detected one.
    det = robocal_detect(robocal, spec, images, os.path.join(tmp, "zhang-detect.json"))
    worst, used = 0.0, 0
    for entry, pts in zip(det["images"], data):
        found = entry.get("detection")
        if not found:
            entry.pop("detection", None)
            entry["error"] = {"kind": "not_found", "message": "no board"}
            continue
        det_xy = np.array([[p["x_px"], p["y_px"]] for p in found["points"]])
        nearest = [int(np.argmin(((det_xy - q) ** 2).sum(1))) for q in pts]
        if len(set(nearest)) != len(pts):
            sys.exit("zhang1998: his corners do not match robocal's one to one")
        worst = max(worst, max(float(np.hypot(*(det_xy[n] - q))) for n, q in zip(nearest, pts)))
        found["points"] = [{"id": found["points"][n]["id"], "x_px": float(q[0]), "y_px": float(q[1])}
                           for n, q in zip(nearest, pts)]
        used += 1
    path = os.path.join(tmp, "zhang-his-corners.json")
    with open(path, "w") as f:
        json.dump(det, f)
    rc = robocal_intrinsics(robocal, ["--detections", path], flags, os.path.join(tmp, "zhang-corners.json"))
    obj = [np.hstack([model, np.zeros((len(model), 1))]).astype(np.float32).reshape(-1, 1, 3)] * 5
    img = [p.astype(np.float32).reshape(-1, 1, 2) for p in data]
    cv = cv_calibrate(obj, img, (640, 480), cv_flags)
    name = "Zhang 1998, his corners"
    add_rows(name, params, ref, None, rc, cv)
    note(f"{name}: {used} views matched to robocal's detection (farthest {worst:.2f} px); robocal rms "
         f"{rc['rms']:.4f} px, OpenCV rms {cv['rms']:.4f} px (no skew)")

    rc = robocal_intrinsics(robocal, ["--target", spec, *images], flags, os.path.join(tmp, "zhang-images.json"))
    add_rows("Zhang 1998, his photos", params, ref, None, rc, None)
    note(f"Zhang 1998, his photos: robocal {rc['views']} views rms {rc['rms']:.4f} px; OpenCV has no "
         "detector for separated squares")


def calib1(robocal, tmp):
    d = dataset_dir("opencv-calib1-dat")
    if not d:
        return note("skipped opencv-calib1-dat: folder not found in ../shared/datasets")
    with open(os.path.join(d, "calib1.dat")) as f:
        text = f.read().split("#")[0]
    v = [float(x) for x in text.split()]
    (w, h, cols, rows, n), at = [int(x) for x in v[:5]], 6
    npt = cols * rows
    obj = np.array(v[at:at + n * npt * 3]).reshape(n, npt, 3)
    at += n * npt * 3
    img = np.array(v[at:at + n * npt * 2]).reshape(n, npt, 2)
    at += n * npt * 2
    ref = dict(zip(["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"], v[at:at + 8]))
    at += 8 + n * 12
    # The file's uncertainty block: fc cc kc errors as the toolbox printed
    # them (its "3 sigma"); given here as they are, their ratio to OpenCV's
    # std is printed.
    errors = v[at:at + 8]
    ref_std = dict(zip(["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"], errors))
    pitch = obj[0, 1, 0] - obj[0, 0, 0]
    if not np.allclose(obj[0, :, :2], [[i * pitch, j * pitch] for j in range(rows) for i in range(cols)]):
        sys.exit("calib1.dat: object points are not a row-major grid")
    det = {"images": [{"file": f"view{k + 1}", "detection": {
        "image_size_px": [w, h], "polarity": "dark_on_light",
        "target": {"kind": "chessboard", "cols": cols, "rows": rows, "square_m": pitch / 100},
        "points": [{"id": i, "x_px": float(p[0]), "y_px": float(p[1])} for i, p in enumerate(img[k])]}}
        for k in range(n)]}
    path = os.path.join(tmp, "calib1-detections.json")
    with open(path, "w") as f:
        json.dump(det, f)
    rc = robocal_intrinsics(robocal, ["--detections", path], ["--fix", "k3"], os.path.join(tmp, "calib1.json"))
    cv = cv_calibrate([o.astype(np.float32).reshape(-1, 1, 3) for o in obj],
                      [p.astype(np.float32).reshape(-1, 1, 2) for p in img], (w, h), cv2.CALIB_FIX_K3)
    name = "Bouguet calib1.dat (points)"
    add_rows(name, ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"], ref, ref_std, rc, cv)
    note(f"{name}: ref ± = the file's uncertainty block as it is; its ratio to OpenCV's std: "
         f"fx {errors[0] / cv['std']['fx']:.2f}, cx {errors[2] / cv['std']['cx']:.2f}; "
         f"robocal rms {rc['rms']:.4f} px, OpenCV rms {cv['rms']:.4f} px")


def toml_cameras(path):
    """camera_array.toml's [cameras.N] matrix and distortions (the few keys
    needed; python 3.11's tomllib when present)."""
    try:
        import tomllib

        with open(path, "rb") as f:
            cams = tomllib.load(f)["cameras"]
        return {int(c): (v["matrix"], v["distortions"], v["error"]) for c, v in cams.items()}
    except ImportError:
        sys.exit("caliscope: needs python >= 3.11 (tomllib)")


def caliscope(robocal, tmp):
    d = dataset_dir("caliscope-4cam-charuco-video")
    if not d:
        return note("skipped caliscope-4cam-charuco-video: folder not found in ../shared/datasets")
    cams = toml_cameras(os.path.join(d, "video", "camera_array.toml"))
    params = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"]
    for cam, (k, dist, error) in sorted(cams.items()):
        ref = {"fx": k[0][0], "fy": k[1][1], "cx": k[0][2], "cy": k[1][2], **dict(zip(COEFFS, dist))}
        frames = os.path.join(tmp, f"cam{cam}")
        os.makedirs(frames, exist_ok=True)
        video = cv2.VideoCapture(os.path.join(d, "video", f"cam_{cam}.mp4"))
        images, i = [], 0
        while True:
            ok, frame = video.read()
            if not ok:
                break
            path = os.path.join(frames, f"f{i:04d}.png")
            cv2.imwrite(path, frame)
            images.append(path)
            i += 1
        rc = robocal_intrinsics(robocal, ["--target", CHARUCO, *images], [], os.path.join(tmp, f"cam{cam}.json"))
        obj, img, size = cv_charuco(images)
        cv = cv_calibrate(obj, img, size, 0)
        name = f"caliscope cam {cam}, video ({len(images)} frames)"
        add_rows(name, params, ref, None, rc, cv)
        note(f"{name}: robocal {rc['views']} views rms {rc['rms']:.4f} px, OpenCV {cv['views']} views rms "
             f"{cv['rms']:.4f} px; caliscope's error {error} px")
    still = sorted(glob.glob(os.path.join(d, "chessboard_intrinsic", "cam_0_frame_*.jpg")))
    k, dist, _ = cams[0]
    ref = {"fx": k[0][0], "fy": k[1][1], "cx": k[0][2], "cy": k[1][2], **dict(zip(COEFFS, dist))}
    rc = robocal_intrinsics(robocal, ["--target", "chessboard:9x6:25mm", *still], [], os.path.join(tmp, "still.json"))
    obj, img, size, found = cv_chessboard(still, 9, 6, 11)
    cv = cv_calibrate([o * 25 for o in obj], img, size, 0) if len(obj) >= 3 else None
    name = "caliscope cam 0, chessboard_intrinsic frames"
    # Four near-frontal views pin no distortion down: the focal length and
    # the principal point only.
    add_rows(name, ["fx", "fy", "cx", "cy"], ref, None, rc, cv)
    note(f"{name}: robocal {rc['views']} views, OpenCV {len(obj)} ({', '.join(found)}); square size unknown")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
    ap.add_argument("--keep", help="keep the reports and frames in this folder")
    ap.add_argument("--sets", default="left_right,zhang,calib1,caliscope,rwhe")
    a = ap.parse_args()
    if not os.path.exists(a.robocal):
        sys.exit(f"no robocal at {a.robocal}: cargo build --release --bin robocal, or --robocal PATH")
    tmp = a.keep or tempfile.mkdtemp(prefix="real_sets_")
    os.makedirs(tmp, exist_ok=True)
    print(f"robocal {a.robocal}, OpenCV {cv2.__version__}")
    for s in a.sets.split(","):
        if s == "rwhe":
            if dataset_dir("rwhe-calib-cs-synthetic-1"):
                note("skipped rwhe-calib-cs-synthetic-1: no published intrinsics (SOURCE.md: not shipped)")
            else:
                note("skipped rwhe-calib-cs-synthetic-1: folder not found in ../shared/datasets")
            continue
        {"left_right": left_right, "zhang": zhang, "calib1": calib1, "caliscope": caliscope}[s](a.robocal, tmp)
    print_table()
    if not a.keep:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
