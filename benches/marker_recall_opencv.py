#!/usr/bin/env python3
"""OpenCV 4.14 against robocal on the small, low-contrast marker boards of
tests/detect/detect_marker_recall.rs (issue 36; BENCHMARKS.md section 2),
on the same PNGs.

Usage (crate root):
  cargo run --example marker_recall_set -- OUT_DIR
  /work/cvenv/bin/python benches/marker_recall_opencv.py OUT_DIR

The example renders the test's ChArUco 10x7 DICT_4X4_50 (markers 16-21 px)
and AprilGrid 7x5 (tags 18-24 px) in its six poses and three conditions
and detects them with robocal (OUT_DIR/recall.json). Here, one thread:
- ChArUco: CharucoDetector with tryRefineMarkers (OpenCV's refinement of
  undetected markers from the board), corners by id;
- AprilGrid: ArucoDetector DICT_APRILTAG_36h11, markerBorderBits 2, alone
  and followed by refineDetectedMarkers with the board (a cv2.aruco.Board
  of the grid's tags); OpenCV has no AprilGrid detector and its tag corners
  are unrefined, so a tag counts by its id, its corners by the nearest
  truth corner of that tag.
Per set and in total: corners within 0.5 px (the test's criterion) and
within 1.5 px of their truth point, of the corners in view; other points
("false": a wrong id, or off by more than 1.5 px; for AprilGrid tags off
by more than 3 px); markers (ChArUco) or tags (AprilGrid) read.
"""
import json
import os
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "out", "marker_recall")
NEAR, FOUND, TAG_OFF = 0.5, 1.5, 3.0


def by_id(found, truth):
    """(within NEAR, within FOUND, false) of [[id, x, y]] against truth by id."""
    t = {int(i): (x, y) for i, x, y in truth}
    near = ok = bad = 0
    for i, x, y in found:
        if int(i) not in t:
            bad += 1
            continue
        e = np.hypot(x - t[int(i)][0], y - t[int(i)][1])
        near += e <= NEAR
        ok += e <= FOUND
        bad += e > FOUND
    return near, ok, bad


def charuco(spec):
    p = spec.split(":")
    sx, sy = map(int, p[1].split("x"))
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, p[4]))
    board = cv2.aruco.CharucoBoard((sx, sy), float(p[2][:-2]) / 1000, float(p[3][:-2]) / 1000, d)
    cp = cv2.aruco.CharucoParameters()
    cp.tryRefineMarkers = True
    det = cv2.aruco.CharucoDetector(board, cp)

    def run(g):
        corners, ids, _, marker_ids = det.detectBoard(g)
        pts = [] if ids is None else [[int(i), float(c[0]), float(c[1])]
                                      for i, c in zip(ids.ravel(), corners.reshape(-1, 2))]
        return pts, 0 if marker_ids is None else len(marker_ids)

    return run


def aprilgrid(spec, markers, refine):
    cols = int(spec.split(":")[1].split("x")[0])
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    dp = cv2.aruco.DetectorParameters()
    dp.markerBorderBits = 2
    det = cv2.aruco.ArucoDetector(d, dp)
    obj = [np.array([[x, y, 0.0] for x, y in m[1]], np.float32) for m in markers]
    board = cv2.aruco.Board(obj, d, np.array([m[0] for m in markers], np.int32))

    def tag_points(k):
        tr, tc = divmod(k, cols)
        return [r * 2 * cols + c for r in (2 * tr, 2 * tr + 1) for c in (2 * tc, 2 * tc + 1)]

    def run(g, truth):
        corners, ids, rejected = det.detectMarkers(g)
        if refine:
            corners, ids, _, _ = det.refineDetectedMarkers(g, board, corners, ids, rejected)
        t = {int(i): (x, y) for i, x, y in truth}
        near = ok = bad = tags = 0
        for c, i in zip(corners or [], [] if ids is None else ids.ravel()):
            mine = [t[p] for p in tag_points(int(i)) if p in t] if int(i) < len(markers) else []
            if not mine:
                bad += 1
                continue
            e = [min(np.hypot(x - tx, y - ty) for tx, ty in mine) for x, y in c.reshape(4, 2)]
            if max(e) > TAG_OFF:
                bad += 1
                continue
            tags += 1
            near += sum(v <= NEAR for v in e)
            ok += sum(v <= FOUND for v in e)
        return near, ok, bad, tags

    return run


def main():
    cv2.setNumThreads(1)
    sets = json.load(open(os.path.join(OUT, "recall.json")))
    print(f"OpenCV {cv2.__version__}; corners within {NEAR} px / within {FOUND} px of their truth, "
          f"of the corners in view; false points; markers or tags read")
    print("| board, condition | corners in view | robocal | OpenCV | OpenCV + refineDetectedMarkers |")
    print("|---|---|---|---|---|")
    totals = {}
    for s in sets:
        total = sum(len(im["truth"]) for im in s["images"])
        row = [0, 0, 0]
        for im in s["images"]:
            for k, v in enumerate(by_id(im["robocal"] or [], im["truth"])):
                row[k] += v
        cols = [f"{row[0]} / {row[1]}, {row[2]} false"]
        if s["kind"] == "charuco":
            run = charuco(s["spec"])
            o = [0, 0, 0, 0]
            for im in s["images"]:
                pts, markers = run(cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE))
                for k, v in enumerate(by_id(pts, im["truth"])):
                    o[k] += v
                o[3] += markers
            cols += [f"{o[0]} / {o[1]}, {o[2]} false, {o[3]} markers (tryRefineMarkers)", "(as left)"]
            runs = [o, o]
        else:
            runs = []
            for refine in (False, True):
                run = aprilgrid(s["spec"], s["markers"], refine)
                o = [0, 0, 0, 0]
                for im in s["images"]:
                    for k, v in enumerate(run(cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE), im["truth"])):
                        o[k] += v
                cols.append(f"{o[0]} / {o[1]}, {o[2]} false, {o[3]} tags")
                runs.append(o)
        tot = totals.setdefault(s["kind"], [0, [0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]])
        tot[0] += total
        tot[1] = [a + b for a, b in zip(tot[1], row)]
        tot[2] = [a + b for a, b in zip(tot[2], runs[0])]
        tot[3] = [a + b for a, b in zip(tot[3], runs[1])]
        print(f"| {s['kind']}, {s['condition']} | {total} | " + " | ".join(cols) + " |")
    for kind, (total, r, o, orf) in totals.items():
        unit = "markers" if kind == "charuco" else "tags"
        print(f"| {kind}, all | {total} | {r[0]} / {r[1]}, {r[2]} false | {o[0]} / {o[1]}, {o[2]} false, "
              f"{o[3]} {unit} | {orf[0]} / {orf[1]}, {orf[2]} false, {orf[3]} {unit} |")


if __name__ == "__main__":
    main()
