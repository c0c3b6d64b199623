#!/usr/bin/env python3
"""CPU time of circle-grid detection, robocal against findCirclesGrid, on the
circle sets of `compare_opencv.py` (benches/out, rendered by
`cargo run --release --example render_set -- benches/out [--quick]`).

CPU time, not wall time, so that the figure holds on a loaded machine.
robocal's per call is the child CPU time (user + sys, getrusage) of a run
of 1 + N calls minus that of a run of 1 call (process start, decoding and
the first call cancel), over N: by default of the release example
`detect_time --repeat 1 + N` (detection alone, the image decoded once
outside the timing), with `--cli PATH` of `robocal detect --threads 1`
given the image 1 + N times (each call decodes the PNG). OpenCV's is
time.process_time() around N calls of findCirclesGrid on the decoded image
(column "OpenCV") and of cv2.imread + findCirclesGrid ("+ imread"), one
thread (cv2.setNumThreads(1)). The ratio compares like with like:
detection alone by default, decoding + detection with --cli.

Usage (crate root, after `cargo build --release --example detect_time`):
  python3 benches/circles_cpu.py [--runs N] [--out benches/out] [--cli PATH]
                                 [--truth FILE] [--bin PATH]

--bin: another detect_time binary (e.g. one built before a change).
--truth: another set file in render_set's truth.json format ({set: {target,
opencv_pattern, images: [{file, points}]}}), e.g. dot plates rendered by
`robocal render` (findCirclesGrid reads a dot plate as a symmetric grid).
"""
import json
import os
import resource
import subprocess
import sys
import time

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def arg(name, default):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def child_cpu(cmd):
    """CPU seconds (user + sys) of running `cmd`, and its stdout."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, out


def main():
    ensure_venv()
    import cv2
    import numpy as np

    runs = int(arg("--runs", "20"))
    out_dir = arg("--out", os.path.join(HERE, "out"))
    cli = arg("--cli", None)
    binary = cli or arg("--bin", os.path.join(ROOT, "target", "release", "examples", "detect_time"))
    out_json = os.path.join(out_dir, "circles_cpu.robocal.json")
    truth = json.load(open(arg("--truth", os.path.join(out_dir, "truth.json"))))
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__} findCirclesGrid vs {binary}; CPU ms per call, "
          f"{runs} calls per image; load {os.getloadavg()[0]:.1f}")
    print(f"{'set':38s} {'img':>3s} {'robocal':>10s} {'OpenCV':>10s} {'+ imread':>10s} {'ratio':>7s}  found (robocal, OpenCV)")
    for set_name, s in truth.items():
        if not s["target"].startswith(("circles", "dots")):
            continue
        flags = cv2.CALIB_CB_ASYMMETRIC_GRID if "asymmetric" in s["target"] else cv2.CALIB_CB_SYMMETRIC_GRID
        size = tuple(s["opencv_pattern"])
        r_ms, o_ms, od_ms, ratios, r_found, o_found = [], [], [], [], 0, 0
        for im in s["images"]:
            f = im["file"]
            n = len(im["points"])
            if cli:
                base = [binary, "detect", "--threads", "1", "--target", s["target"], "-o", out_json]
                one, _ = child_cpu(base + [f])
                many, _ = child_cpu(base + [f] * (1 + runs))
                got = json.load(open(out_json))["images"]
                r_found += all(len(g.get("detection", {}).get("points", [])) == n for g in got)
            else:
                base = [binary, "--no-blank", "--target", s["target"], "--repeat"]
                one, _ = child_cpu(base + ["1", f])
                many, out = child_cpu(base + [str(1 + runs), f])
                r_found += f"Some({n}) points" in out
            r = (many - one) / runs * 1000.0
            g = cv2.imread(f, cv2.IMREAD_GRAYSCALE)
            t0 = time.process_time()
            for _ in range(runs):
                ok, _c = cv2.findCirclesGrid(g, size, flags=flags)
            o = (time.process_time() - t0) / runs * 1000.0
            o_found += bool(ok)
            t0 = time.process_time()
            for _ in range(runs):
                cv2.findCirclesGrid(cv2.imread(f, cv2.IMREAD_GRAYSCALE), size, flags=flags)
            od = (time.process_time() - t0) / runs * 1000.0
            r_ms.append(r)
            o_ms.append(o)
            od_ms.append(od)
            ratios.append(r / (od if cli else o))
        k = len(r_ms)
        print(f"{set_name:38s} {k:3d} {np.median(r_ms):10.2f} {np.median(o_ms):10.2f} {np.median(od_ms):10.2f} "
              f"{np.median(ratios):7.3f}  {r_found}/{k}, {o_found}/{k}")
    print("ratio = median over images of robocal / OpenCV CPU time, "
          + ("both decoding the PNG" if cli else "detection alone"))


if __name__ == "__main__":
    main()
