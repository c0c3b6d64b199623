#!/usr/bin/env python3
"""Compare robocal's target detection with OpenCV on rendered image sets.

Creates benches/.venv with the pinned reference (opencv-python-headless
4.14.0.94), renders the sets with `cargo run --release --example
render_set`, runs both detectors single-threaded (robocal: `robocal detect
--threads 1`, detection time measured inside the process without decoding;
OpenCV: cv2.setNumThreads(1), the calls timed around them, decoding
excluded) and prints per set: boards found, mean / max point error against
the renderer's ground truth, median times and the median of the per-image
time ratio robocal / OpenCV.

Usage (crate root):
  python3 benches/compare_opencv.py [--quick] [--skip-render] [--repeat N [--interleave]]

Circle sets also get a row for `robocal detect --circle-centres
ellipse_centre` (the centres without the perspective correction).

--repeat N: run `robocal detect` N times and call each OpenCV function N
times per image; every time is then the per-image median of N (default 1:
one cold call each). On a shared machine single calls vary by 2-3x.
"""
import json
import os
import subprocess
import sys
import time

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUT = os.path.join(HERE, "out")


def errors(found, truth):
    """Mean and max distance; the detector's order may run from either end."""
    import numpy as np

    f = np.asarray(found, float).reshape(-1, 2)
    t = np.asarray(truth, float).reshape(-1, 2)
    if f.shape != t.shape:
        return None
    best = None
    for cand in (f, f[::-1]):
        d = np.sqrt(((cand - t) ** 2).sum(1))
        if best is None or d.mean() < best[0]:
            best = (d.mean(), d.max())
    return best


def opencv_methods(spec, pattern):
    import cv2

    size = tuple(pattern)
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
    if spec.startswith("chessboard"):
        def classic(g):
            ok, c = cv2.findChessboardCorners(g, size)
            if not ok:
                return None
            return cv2.cornerSubPix(g, c, (11, 11), (-1, -1), crit)

        def sb(g):
            ok, c = cv2.findChessboardCornersSB(g, size)
            return c if ok else None

        return {"findChessboardCorners+cornerSubPix": classic, "findChessboardCornersSB": sb}
    flags = cv2.CALIB_CB_ASYMMETRIC_GRID if "asymmetric" in spec else cv2.CALIB_CB_SYMMETRIC_GRID

    def circles(g):
        ok, c = cv2.findCirclesGrid(g, size, flags=flags)
        return c if ok else None

    return {"findCirclesGrid": circles}


def summarize(name, found, errs, times):
    import numpy as np

    e = [x for x in errs if x is not None]
    mean = np.mean([x[0] for x in e]) if e else float("nan")
    mx = np.max([x[1] for x in e]) if e else float("nan")
    return {"name": name, "found": found, "mean": mean, "max": mx, "median_ms": float(np.median(times)) if times else float("nan")}


def main():
    ensure_venv()
    import cv2
    import numpy as np

    quick = "--quick" in sys.argv
    interleave = "--interleave" in sys.argv
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 1
    if "--skip-render" not in sys.argv:
        cmd = ["cargo", "run", "--release", "--example", "render_set", "--", OUT] + (["--quick"] if quick else [])
        subprocess.check_call(cmd, cwd=ROOT)
        subprocess.check_call(["cargo", "build", "--release", "--bin", "robocal"], cwd=ROOT)
    truth = json.load(open(os.path.join(OUT, "truth.json")))
    robocal = os.path.join(ROOT, "target", "release", "robocal")
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}, single-threaded; robocal {robocal} --threads 1; "
          f"times: per-image median of {repeat} run(s)" + (", robocal and the first OpenCV method interleaved" if interleave else ""))
    for set_name, s in truth.items():
        files = [im["file"] for im in s["images"]]
        gts = [im["points"] for im in s["images"]]
        out_json = os.path.join(OUT, set_name + ".robocal.json")
        runs = []
        for _ in range(repeat):
            subprocess.run([robocal, "detect", "--threads", "1", "--target", s["target"], "-o", out_json] + files,
                           cwd=ROOT, stderr=subprocess.DEVNULL)
            runs.append(json.load(open(out_json))["images"])
        res = runs[-1]
        r_err, r_times, r_found = [], [], 0
        for k, (im, gt) in enumerate(zip(res, gts)):
            if "detection" in im:
                r_found += 1
                pts = [[p["x_px"], p["y_px"]] for p in im["detection"]["points"]]
                r_err.append(errors(pts, gt))
                r_times.append(float(np.median([run[k]["detect_ms"] for run in runs])))
            else:
                r_times.append(float("nan"))
        methods = opencv_methods(s["target"], s["opencv_pattern"])
        paired = {}
        if interleave:
            first = next(iter(methods))
            one_json = os.path.join(OUT, "one.robocal.json")
            for k, f in enumerate(files):
                g = cv2.imread(f, cv2.IMREAD_GRAYSCALE)
                rt, ot = [], []
                for _ in range(repeat):
                    subprocess.run([robocal, "detect", "--threads", "1", "--target", s["target"], "-o", one_json, f],
                                   cwd=ROOT, stderr=subprocess.DEVNULL)
                    rt.append(json.load(open(one_json))["images"][0].get("detect_ms", float("nan")))
                    t0 = time.perf_counter()
                    methods[first](g)
                    ot.append((time.perf_counter() - t0) * 1000.0)
                if r_times[k] == r_times[k]:
                    r_times[k] = float(np.median(rt))
                paired[(first, f)] = float(np.median(ot))
        rows = [summarize("robocal", r_found, r_err, [t for t in r_times if t == t])]
        if s["target"].startswith("circles"):
            # The same detector without the perspective correction of circle
            # centres (issue 20), for comparison.
            plain_json = os.path.join(OUT, set_name + ".ellipse.robocal.json")
            subprocess.run([robocal, "detect", "--threads", "1", "--circle-centres", "ellipse_centre",
                            "--target", s["target"], "-o", plain_json] + files, cwd=ROOT, stderr=subprocess.DEVNULL)
            e_err, e_times, e_found = [], [], 0
            for im, gt in zip(json.load(open(plain_json))["images"], gts):
                if "detection" in im:
                    e_found += 1
                    e_err.append(errors([[p["x_px"], p["y_px"]] for p in im["detection"]["points"]], gt))
                    e_times.append(im["detect_ms"])
            rows.append(summarize("robocal --circle-centres ellipse_centre", e_found, e_err, e_times))
        ratios = {}
        for mname, fn in methods.items():
            errs, times, found = [], [], 0
            for f, gt, rt in zip(files, gts, r_times):
                g = cv2.imread(f, cv2.IMREAD_GRAYSCALE)
                tries = []
                for _ in range(1 if (mname, f) in paired else repeat):
                    t0 = time.perf_counter()
                    c = fn(g)
                    tries.append((time.perf_counter() - t0) * 1000.0)
                ms = paired.get((mname, f), float(np.median(tries)))
                times.append(ms)
                if c is not None:
                    found += 1
                    errs.append(errors(c.reshape(-1, 2), gt))
                if rt == rt:
                    ratios.setdefault(mname, []).append(rt / ms)
            rows.append(summarize(mname, found, errs, times))
        h, w = cv2.imread(files[0], cv2.IMREAD_GRAYSCALE).shape
        print(f"\n## {set_name}: {len(files)} images {w}x{h}, target {s['target']}, noise sigma 2")
        print(f"{'detector':38s} {'found':>7s} {'mean px':>8s} {'max px':>8s} {'median ms':>10s} {'ratio':>7s}")
        for r in rows:
            ratio = ratios.get(r["name"])
            rtxt = f"{np.median(ratio):7.3f}" if ratio else "      -"
            print(f"{r['name']:38s} {r['found']:3d}/{len(files):<3d} {r['mean']:8.4f} {r['max']:8.4f} {r['median_ms']:10.2f} {rtxt}")
    print("\nratio = median over images of robocal time / OpenCV time (lower is faster for robocal)")


if __name__ == "__main__":
    main()
