#!/usr/bin/env python3
"""Per target kind and print: recall and point error of robocal and of
OpenCV 4.14 on the same renders (issue 36; BENCHMARKS.md section 1).

`cargo run --example recall_table -- OUT --views N` renders every kind
(chessboard 8x6, ChArUco 12x9 DICT_5X5_100, AprilGrid 6x6, ArUco grid 5x7
DICT_6X6_250, circles 7x5 symmetric, circles 4x11 asymmetric, dots 7x7)
dark on light and light on dark, in a usual and a hard condition (half the
size, blur 1.4 px, print 80 / 170), and detects them with robocal without
a print option. This script runs OpenCV on the same PNGs, told the print
(light-on-dark images are inverted by hand, 255 - grey, as OpenCV needs):
- chessboard: findChessboardCorners + cornerSubPix (5x5 half-window);
- ChArUco: CharucoDetector with tryRefineMarkers (its refinement of
  undetected markers from the board);
- AprilGrid: ArucoDetector DICT_APRILTAG_36h11, markerBorderBits 2;
- ArUco grid: ArucoDetector + refineDetectedMarkers with the GridBoard;
- circles: findCirclesGrid (symmetric / asymmetric);
- dots: OpenCV has no dot-plate detector.
A point counts as found when it lies within 1.5 px of the truth point it
claims (robocal: by id; OpenCV: the nearest truth point, since its marker
corner order and numbering differ from Kalibr's); any other point is
"wrong". Error: mean / max distance of the found points. Times: median
per image of robocal's one `detect` call (wall time in the example's
process, one thread; `robocal_ms`) and of OpenCV's detector call(s) here
(wall time, cv2.setNumThreads(1)); meaningful with the example built in
release (`--release`, the default here).

Usage (crate root): python3 benches/recall_table.py [--views N] [--skip-render] [--debug] [--out DIR]
(renders in DIR, default benches/out/recall; --debug: the example in the
dev profile, times not comparable)
"""
import json
import os
import subprocess
import sys
import time

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out", "recall")
FOUND_PX = 1.5


def arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def spec_parts(spec):
    return spec.split(":")


def opencv_detector(kind, spec):
    import cv2
    import numpy as np

    p = spec_parts(spec)
    if kind == "chessboard":
        cols, rows = map(int, p[1].split("x"))

        def run(g):
            ok, c = cv2.findChessboardCorners(g, (cols, rows))
            if not ok:
                return []
            crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
            c = cv2.cornerSubPix(g, c, (5, 5), (-1, -1), crit)
            return c.reshape(-1, 2).tolist()

        return run
    if kind == "charuco":
        sx, sy = map(int, p[1].split("x"))
        board = cv2.aruco.CharucoBoard((sx, sy), float(p[2][:-2]) / 1000, float(p[3][:-2]) / 1000,
                                       cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, p[4])))
        cp = cv2.aruco.CharucoParameters()
        cp.tryRefineMarkers = True
        det = cv2.aruco.CharucoDetector(board, cp)

        def run(g):
            corners, ids, _, _ = det.detectBoard(g)
            return [] if ids is None else corners.reshape(-1, 2).tolist()

        return run
    if kind == "aprilgrid":
        dp = cv2.aruco.DetectorParameters()
        dp.markerBorderBits = 2
        det = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11), dp)

        def run(g):
            corners, ids, _ = det.detectMarkers(g)
            return [] if ids is None else np.concatenate([c.reshape(4, 2) for c in corners]).tolist()

        return run
    if kind == "arucogrid":
        mx, my = map(int, p[1].split("x"))
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, p[4]))
        board = cv2.aruco.GridBoard((mx, my), float(p[2][:-2]) / 1000, float(p[3][:-2]) / 1000, d)
        det = cv2.aruco.ArucoDetector(d, cv2.aruco.DetectorParameters())

        def run(g):
            corners, ids, rejected = det.detectMarkers(g)
            corners, ids, _, _ = det.refineDetectedMarkers(g, board, corners, ids, rejected)
            return [] if ids is None else np.concatenate([c.reshape(4, 2) for c in corners]).tolist()

        return run
    if kind in ("circles_sym", "circles_asym"):
        cols, rows = map(int, p[1].split("x"))
        flag = cv2.CALIB_CB_ASYMMETRIC_GRID if kind == "circles_asym" else cv2.CALIB_CB_SYMMETRIC_GRID

        def run(g):
            ok, c = cv2.findCirclesGrid(g, (cols, rows), flags=flag)
            return c.reshape(-1, 2).tolist() if ok else []

        return run
    return None


def score_by_id(found, truth):
    t = {int(i): (x, y) for i, x, y in truth}
    d, wrong = [], 0
    for i, x, y in found:
        if int(i) not in t:
            wrong += 1
            continue
        e = ((x - t[int(i)][0]) ** 2 + (y - t[int(i)][1]) ** 2) ** 0.5
        if e <= FOUND_PX:
            d.append(e)
        else:
            wrong += 1
    return d, wrong


def score_nearest(found, truth):
    d, wrong, used = [], 0, set()
    for x, y in found:
        best = min(((x - tx) ** 2 + (y - ty) ** 2, int(i)) for i, tx, ty in truth) if truth else (1e18, -1)
        e = best[0] ** 0.5
        if e <= FOUND_PX and best[1] not in used:
            used.add(best[1])
            d.append(e)
        else:
            wrong += 1
    return d, wrong


def cell(d, total, wrong):
    if total == 0:
        return "-"
    if not d:
        return f"0/{total} ({wrong} wrong)"
    w = f", {wrong} wrong" if wrong else ""
    return f"{len(d)}/{total} ({100 * len(d) / total:.0f} %), {sum(d) / len(d):.4f} / {max(d):.3f} px{w}"


def median(v):
    if not v:
        return "-"
    v = sorted(v)
    return f"{v[len(v) // 2]:.1f}" if len(v) % 2 else f"{0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2]):.1f}"


def main():
    ensure_venv()
    import cv2

    views = arg("--views", 6)
    out = sys.argv[sys.argv.index("--out") + 1] if "--out" in sys.argv else OUT
    if "--skip-render" not in sys.argv:
        profile = [] if "--debug" in sys.argv else ["--release"]
        subprocess.check_call(["cargo", "run", *profile, "--example", "recall_table", "--", out,
                               "--views", str(views)], cwd=ROOT)
    sets = json.load(open(os.path.join(out, "recall.json")))
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}; found = within {FOUND_PX} px of its truth point; cells: found/in view "
          f"(recall), mean / max px of the found points, wrong points; median ms per image")
    print("| kind | print | condition | robocal | OpenCV 4.14 | robocal / OpenCV ms |")
    print("|---|---|---|---|---|---|")
    for s in sets:
        fn = opencv_detector(s["kind"], s["spec"])
        rd, rw, od, ow, total = [], 0, [], 0, 0
        rms, oms = [], []
        for im in s["images"]:
            if "robocal_ms" in im:
                rms.append(im["robocal_ms"])
            total += len(im["truth"])
            d, w = score_by_id(im["robocal"] or [], im["truth"])
            rd += d
            rw += w
            if fn is not None:
                g = cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE)
                if s["print"] == "light_on_dark":
                    g = 255 - g
                t0 = time.perf_counter()
                found = fn(g)
                oms.append(1e3 * (time.perf_counter() - t0))
                d, w = score_nearest(found, im["truth"])
                od += d
                ow += w
        ocv = cell(od, total, ow) if fn is not None else "none (no detector)"
        print(f"| {s['kind']} | {s['print']} | {s['condition']} | {cell(rd, total, rw)} | {ocv} | "
              f"{median(rms)} / {median(oms)} |")


if __name__ == "__main__":
    main()
