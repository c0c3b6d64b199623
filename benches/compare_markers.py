#!/usr/bin/env python3
"""Compare robocal's marker-board detection (ChArUco, AprilGrid) with
OpenCV 4.14 on seeded renders of the project's renderer (issue 18).

`cargo run --release --example marker_compare` renders the sets (1280x960,
noise sigma 2 grey levels, blur 0.7 px: ChArUco 12x9 DICT_5X5_100 full and
partial views, the chessboard with the same corners at the same poses,
AprilGrid 6x6 full and partial, board-free images: chessboard
renders, uniform noise, synth::clutter) and times robocal's
`detect` in its own process (one thread, decoding excluded, median of
--repeat calls per image). This script runs OpenCV single-threaded
(cv2.setNumThreads(1)) on the same PNGs, timing the call alone (decoding
excluded, median of --repeat calls): `cv2.aruco.CharucoDetector.detectBoard`
on the ChArUco sets and `ArucoDetector` with DICT_APRILTAG_36h11 on the
AprilGrids (markerBorderBits 2: Kalibr's tags have a two-bit black
border). Errors are against the renderer's exact truth, by corner id.

Usage (crate root):
  python3 benches/compare_markers.py [--views N] [--repeat N] [--skip-render]
"""
import json
import os
import subprocess
import sys
import time

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out", "markers")


def arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def timed(fn, g, repeat):
    ts, r = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = fn(g)
        ts.append((time.perf_counter() - t0) * 1000.0)
    ts.sort()
    return ts[len(ts) // 2], r


def by_id_errors(found, truth):
    """Distances of found [[id, x, y]] to the truth with the same id, and
    the number of found ids not in view (wrong ids)."""
    t = {int(i): (x, y) for i, x, y in truth}
    d, wrong = [], 0
    for i, x, y in found:
        if int(i) not in t:
            wrong += 1
            continue
        tx, ty = t[int(i)]
        d.append(((x - tx) ** 2 + (y - ty) ** 2) ** 0.5)
    return d, wrong


def opencv_charuco():
    import cv2

    board = cv2.aruco.CharucoBoard((12, 9), 0.020, 0.015, cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_5X5_100))
    det = cv2.aruco.CharucoDetector(board)

    def run(g):
        corners, ids, _, _ = det.detectBoard(g)
        if ids is None:
            return []
        return [[int(i), float(c[0][0]), float(c[0][1])] for i, c in zip(ids.ravel(), corners)]

    return run


def opencv_apriltag(border_bits):
    import cv2

    p = cv2.aruco.DetectorParameters()
    p.markerBorderBits = border_bits
    det = cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11), p)

    def run(g):
        corners, ids, _ = det.detectMarkers(g)
        return [] if ids is None else list(zip(ids.ravel().tolist(), [c.reshape(4, 2) for c in corners]))

    return run


def tag_corner_errors(markers, truth):
    """OpenCV's tag corners matched to the nearest truth corner of the
    whole grid (its corner order and the tag-to-point numbering differ from
    Kalibr's; the gap between tags is far larger than any corner error)."""
    import numpy as np

    t = np.asarray([[x, y] for _, x, y in truth], float).reshape(-1, 2)
    d = []
    for _, quad in markers:
        for x, y in quad:
            d.append(float(np.sqrt(((t - [x, y]) ** 2).sum(1)).min()))
    return d


def stats(d):
    import numpy as np

    return (float(np.mean(d)), float(np.max(d))) if d else (float("nan"), float("nan"))


def main():
    ensure_venv()
    import cv2
    import numpy as np

    views, repeat = arg("--views", 10), arg("--repeat", 5)
    if "--skip-render" not in sys.argv:
        subprocess.check_call(["cargo", "run", "--release", "--example", "marker_compare", "--", OUT,
                               "--views", str(views), "--repeat", str(repeat)], cwd=ROOT)
    sets = json.load(open(os.path.join(OUT, "markers.json")))
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}, single-threaded; robocal examples/marker_compare (in-process detect, "
          f"one thread); times: per-image median of {repeat} call(s), decoding excluded")
    print(f"\n{'set / detector':44s} {'images':>7s} {'corners':>13s} {'mean px':>8s} {'max px':>8s} "
          f"{'wrong id':>8s} {'median ms':>9s} {'ratio':>6s}")
    charuco, tags = opencv_charuco(), {1: opencv_apriltag(1), 2: opencv_apriltag(2)}
    for name, s in sets.items():
        if name == "board_free":
            continue
        rows = {}
        is_april = s["target"].startswith("aprilgrid")
        methods = {"robocal": None}
        if s["target"].startswith("charuco"):
            methods["OpenCV CharucoDetector"] = charuco
        if is_april:
            methods["OpenCV ArucoDetector 36h11 border 2"] = tags[2]
            methods["OpenCV ArucoDetector 36h11 border 1"] = tags[1]
        robo_ms = []
        for mname, fn in methods.items():
            errs, wrong, found, total, ms, ratio = [], 0, 0, 0, [], []
            for im in s["images"]:
                total += len(im["truth"])
                if fn is None:
                    r = im["robocal"]
                    pts, t = r["points"] or [], r["ms"]
                    robo_ms.append(t)
                    d, w = by_id_errors(pts, im["truth"])
                else:
                    g = cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE)
                    t, pts = timed(fn, g, repeat)
                    if is_april:
                        d, w = tag_corner_errors(pts, im["truth"]), 0
                    else:
                        d, w = by_id_errors(pts, im["truth"])
                    ratio.append(robo_ms[len(ms)] / t)
                errs += d
                wrong += w
                found += len(d)
                ms.append(t)
            m, mx = stats(errs)
            rtxt = f"{np.median(ratio):6.2f}" if ratio else "     -"
            print(f"{name + ' / ' + mname:44s} {len(s['images']):7d} {found:6d}/{total:<6d} {m:8.4f} {mx:8.4f} "
                  f"{wrong:8d} {np.median(ms):9.2f} {rtxt}")
    free = sets["board_free"]
    worst = []
    for name, s in sets.items():
        for im in s["images"] if name != "board_free" else []:
            d, _ = by_id_errors(im["robocal"]["points"] or [], im["truth"])
            worst += [(e, name, os.path.basename(im["file"])) for e in d if e > 0.2]
    print("\nrobocal corners off by more than 0.2 px:", sorted(worst, reverse=True) or "none")
    print(f"\nboard-free images ({len(free['images'])}: chessboard renders, uniform noise, clutter):")
    kinds = sorted({os.path.basename(os.path.dirname(im["file"])) for im in free["images"]})
    for kind in kinds:
        ims = [im for im in free["images"] if os.path.basename(os.path.dirname(im["file"])) == kind]
        print(f" {kind} ({len(ims)} images):")
        for spec in free["targets"]:
            n = sum(1 for im in ims if im["robocal"][spec]["points"])
            ms = np.median([im["robocal"][spec]["ms"] for im in ims])
            print(f"  robocal {spec}: {n} images with a detection, median {ms:.2f} ms")
        for label, fn in [("OpenCV CharucoDetector", charuco), ("OpenCV ArucoDetector 36h11 border 2", tags[2]),
                          ("OpenCV ArucoDetector 36h11 border 1", tags[1])]:
            n, ms = 0, []
            for im in ims:
                g = cv2.imread(im["file"], cv2.IMREAD_GRAYSCALE)
                t, pts = timed(fn, g, repeat)
                ms.append(t)
                n += len(pts)
            print(f"  {label}: {n} corners/markers in total, median {np.median(ms):.2f} ms")
    print("\nratio = median over images of robocal time / OpenCV time (same images; lower is faster for robocal)")


if __name__ == "__main__":
    main()
