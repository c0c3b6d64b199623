#!/usr/bin/env python3
"""External readers for robocal's exports: OpenCV reads what we write.

For a few cameras (Brown, rational with thin prism, fisheye) this script
asks `robocal export` for OpenCV YAML and XML, ROS camera_info and Kalibr
YAML, then reads them back with cv2.FileStorage (opencv-python-headless
4.14.0.94, pinned in benches/opencv_venv.py) and PyYAML, and compares every number with the input.
For the 3-camera rig of fixtures/exports/rig.json (issue 22) it reads the
rig's OpenCV FileStorage (R_k, T_k, camera_matrix_k per camera) with
cv2.FileStorage, and its Kalibr camchain and ROS camera_infos with PyYAML,
chaining Kalibr's T_cn_cnm1 back to every camera_from_rig. The rig's mrcal
.cameramodel files are read by mrcal's own reader (mrcal.cameramodel, from
Debian's python3-mrcal, run with the system python3 since mrcal is not on
the venv): lens model, intrinsics and extrinsics_rt_fromref against the
report; skipped with a note when `import mrcal` fails.

Usage (creates benches/.venv on first run; needs target/release/robocal):
    cargo build --release && python3 benches/check_exports.py
Exit code 0 when every file reads back exactly.
"""
import json
import os
import subprocess
import sys
import tempfile

from opencv_venv import ensure_venv

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
# ROBOCAL_BIN overrides the binary (e.g. target/debug/robocal of a test run).
ROBOCAL = os.environ.get("ROBOCAL_BIN") or os.path.join(ROOT, "target", "release", "robocal")


CAMERAS = {
    "brown": {"model": "brown", "distortion": {"k1": -0.2286, "k2": 0.1904, "p1": 0.00123, "p2": -0.000456, "k3": -0.0123}},
    "rational": {"model": "rational", "distortion": {"k1": 0.1, "k2": 0.01, "p1": 0.001, "p2": -0.001, "k3": 0.001,
                                                     "k4": 0.2, "k5": 0.02, "k6": 0.002, "s1": 1e-4, "s2": 2e-4, "s3": -1e-4, "s4": 5e-5}},
    "kannala_brandt": {"model": "kannala_brandt", "distortion": {"k1": 0.01, "k2": -0.002, "k3": 0.0003, "k4": -4e-5}},
}
OPENCV_ORDER = {"brown": ["k1", "k2", "p1", "p2", "k3"],
                "rational": ["k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"],
                "kannala_brandt": ["k1", "k2", "k3", "k4"]}


def export(report_path, fmt):
    return subprocess.run([ROBOCAL, "export", report_path, "--format", fmt], check=True, capture_output=True, text=True).stdout


def main():
    ensure_venv()
    import cv2
    import numpy as np
    import yaml

    failures = 0
    K = [812.3456789, 0.0, 319.75, 0.0, 815.25, 241.125, 0.0, 0.0, 1.0]
    with tempfile.TemporaryDirectory() as tmp:
        for name, cam in CAMERAS.items():
            report = {"name": "cam0", "image_size_px": [640, 480], "camera_matrix": K, "rms_px": 0.25, **cam}
            path = os.path.join(tmp, f"{name}.json")
            with open(path, "w") as f:
                json.dump(report, f)
            want_d = [cam["distortion"][k] for k in OPENCV_ORDER[name]]
            for fmt, ext in [("opencv-yaml", "yaml"), ("opencv-xml", "xml")]:
                out = os.path.join(tmp, f"{name}.{ext}")
                with open(out, "w") as f:
                    f.write(export(path, fmt))
                fs = cv2.FileStorage(out, cv2.FILE_STORAGE_READ)
                k = fs.getNode("camera_matrix").mat().reshape(-1).tolist()
                d = fs.getNode("distortion_coefficients").mat().reshape(-1).tolist()
                w = int(fs.getNode("image_width").real())
                ok = k == K and d == want_d and w == 640
                failures += not ok
                print(f"{'ok  ' if ok else 'FAIL'} cv2.FileStorage reads {fmt:12s} {name}")
            ros = yaml.safe_load(export(path, "ros-yaml"))
            ok = ros["camera_matrix"]["data"] == K and ros["distortion_coefficients"]["data"] == want_d
            failures += not ok
            print(f"{'ok  ' if ok else 'FAIL'} PyYAML reads ros-yaml             {name} ({ros['distortion_model']})")
    failures += check_rig(cv2, np, yaml)
    print("all exports read back exactly" if not failures else f"{failures} export(s) did not read back")
    return 1 if failures else 0


# Rotations pass through a quaternion inside robocal (the report's pose is
# read back as matrix + quaternion): 1e-12 covers that rounding.
RIG_TOL = 1e-12


def check_rig(cv2, np, yaml):
    """Read the rig exports of fixtures/exports/rig.json with their tools."""
    rig_path = os.path.join(ROOT, "fixtures", "exports", "rig.json")
    with open(rig_path) as f:
        rig = json.load(f)
    truth = [np.array(c["camera_from_rig"]["matrix_row_major"]) for c in rig["cameras"]]
    names = [c["name"] for c in rig["cameras"]]
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "rig.opencv.yaml")
        with open(out, "w") as f:
            f.write(export(rig_path, "opencv-yaml"))
        fs = cv2.FileStorage(out, cv2.FILE_STORAGE_READ)
        n = int(fs.getNode("camera_count").real())
        worst = 0.0
        ok = n == len(names)
        for k in range(n):
            r = fs.getNode(f"R_{k}").mat()
            t = fs.getNode(f"T_{k}").mat().reshape(-1)
            worst = max(worst, np.abs(r - truth[k][:3, :3]).max(), np.abs(t - truth[k][:3, 3]).max())
            cam = rig["cameras"][k]["calibration"]
            ok = ok and fs.getNode(f"name_{k}").string() == names[k]
            ok = ok and fs.getNode(f"camera_matrix_{k}").mat().tolist() == cam["camera_matrix"]
        ok = ok and worst < RIG_TOL
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} cv2.FileStorage reads rig opencv-yaml {n} cameras (R_k, T_k within {worst:.1e} of camera_from_rig)")

        chain = yaml.safe_load(export(rig_path, "kalibr"))
        cam_from_rig = np.eye(4)
        worst = 0.0
        ok = len(chain) == len(names)
        for k in range(len(chain)):
            entry = chain[f"cam{k}"]
            if k > 0:
                cam_from_rig = np.array(entry["T_cn_cnm1"]) @ cam_from_rig
            worst = max(worst, np.abs(cam_from_rig - truth[k]).max())
            ok = ok and entry["rostopic"] == f"/{names[k]}/image_raw"
        ok = ok and worst < RIG_TOL
        failures += not ok
        overlaps = [chain[f"cam{k}"]["cam_overlaps"] for k in range(len(chain))]
        print(f"{'ok  ' if ok else 'FAIL'} PyYAML reads rig kalibr camchain: T_cn_cnm1 chained within {worst:.1e} of camera_from_rig, cam_overlaps {overlaps}")

        folder = os.path.join(tmp, "ros")
        subprocess.run([ROBOCAL, "export", rig_path, "--format", "ros", "-o", folder], check=True, capture_output=True)
        ok = True
        for k, name in enumerate(names):
            with open(os.path.join(folder, f"{name}.yaml")) as f:
                info = yaml.safe_load(f)
            want = [x for row in rig["cameras"][k]["calibration"]["camera_matrix"] for x in row]
            ok = ok and info["camera_name"] == name and info["camera_matrix"]["data"] == want
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} PyYAML reads rig ros camera_info x{len(names)}")
        failures += check_rig_mrcal(rig_path, rig, names, truth, np, tmp)
    return failures


# Read by mrcal (system python3): every .cameramodel's lens model,
# intrinsics and rt_cam_ref, and camera_from_rig rebuilt with mrcal's own
# Rodrigues (mrcal.R_from_r).
MRCAL_READER = """
import json, sys, mrcal
out = {}
for path in sys.argv[1:]:
    m = mrcal.cameramodel(path)
    lens, intr = m.intrinsics()
    rt = m.extrinsics_rt_fromref()
    out[path] = {"lensmodel": lens, "intrinsics": intr.tolist(), "rt": rt.tolist(),
                 "R": mrcal.R_from_r(rt[:3]).tolist(), "size": [int(v) for v in m.imagersize()],
                 "version": mrcal.__version__ if hasattr(mrcal, "__version__") else "?"}
print(json.dumps(out))
"""


def check_rig_mrcal(rig_path, rig, names, truth, np, tmp):
    # mrcal has no Kannala-Brandt model (robocal refuses to write one): the
    # check reads the rig without such cameras.
    keep = [k for k, c in enumerate(rig["cameras"]) if c["calibration"]["model"] != "kannala_brandt"]
    rig = json.loads(json.dumps(rig))
    kept = [names[k] for k in keep]
    rig["cameras"] = [rig["cameras"][k] for k in keep]
    co = rig["co_observation"]
    co["frames"] = [[co["frames"][i][j] for j in keep] for i in keep]
    co["cameras"] = kept
    co["spanning_tree"] = []
    for f in rig["frames"]:
        f["cameras"] = [c for c in f["cameras"] if c in kept]
    names, truth = kept, [truth[k] for k in keep]
    rig_path = os.path.join(tmp, "rig_for_mrcal.json")
    with open(rig_path, "w") as f:
        json.dump(rig, f)
    folder = os.path.join(tmp, "mrcal")
    subprocess.run([ROBOCAL, "export", rig_path, "--format", "mrcal", "-o", folder], check=True, capture_output=True)
    files = [os.path.join(folder, f"{name}.cameramodel") for name in names]
    run = subprocess.run(["/usr/bin/python3", "-c", MRCAL_READER, *files], capture_output=True, text=True)
    if run.returncode != 0:
        print(f"skip mrcal reader not available (apt-get install python3-mrcal): {run.stderr.strip().splitlines()[-1:]}")
        return 0
    read = json.loads(run.stdout)
    worst = 0.0
    ok = True
    for k, path in enumerate(files):
        m = read[path]
        cam = rig["cameras"][k]["calibration"]
        K = cam["camera_matrix"]
        ok = ok and m["intrinsics"][:4] == [K[0][0], K[1][1], K[0][2], K[1][2]]
        if m["lensmodel"] == "LENSMODEL_OPENCV5":
            ok = ok and m["intrinsics"][4:] == [cam["distortion"][c] for c in OPENCV_ORDER["brown"]]
        ok = ok and m["size"] == cam["image_size_px"]
        worst = max(worst, np.abs(np.array(m["R"]) - truth[k][:3, :3]).max(),
                    np.abs(np.array(m["rt"][3:]) - truth[k][:3, 3]).max())
    ok = ok and worst < RIG_TOL
    lens = sorted({read[p]["lensmodel"] for p in files})
    print(f"{'ok  ' if ok else 'FAIL'} mrcal.cameramodel reads rig mrcal x{len(names)} ({', '.join(lens)}; "
          f"extrinsics within {worst:.1e} of camera_from_rig)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
