#!/usr/bin/env python3
"""BENCHMARKS section 6: robocal's 4-camera rig from caliscope's raw videos
against caliscope's own camera_array.toml (issue 36, recordings).

Usage: benches/caliscope_rig.py RIG.json [DATASET_DIR]
RIG.json is the report of
  robocal rig --target charuco:4x5:54mm:40.5mm:DICT_4X4_1000 --still-px any \
      --video-keep sharp --camera cam0 video/cam_0.mp4 ... --camera cam3 video/cam_3.mp4 \
      --timestamps video/timestamps.csv -o RIG.json

Caliscope's (rotation, translation) are camera_from_world: its
CameraData.projection_matrix is matrix @ [rotation | translation] (the
OpenCV rvec/tvec convention), whatever its field comments say. So
camera_i_from_camera_0 = T_i @ inv(T_0), robocal's camera_from_rig with the
rig frame camera 0's.
"""
import json
import math
import sys
import tomllib
from pathlib import Path

import numpy as np


def pose(rotation, translation):
    t = np.eye(4)
    t[:3, :3] = np.array(rotation, float)
    t[:3, 3] = np.array(translation, float)
    return t


def angle_deg(r):
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0))))


def main():
    rig = json.loads(Path(sys.argv[1]).read_text())
    root = Path(sys.argv[2] if len(sys.argv) > 2 else "../shared/datasets/caliscope-4cam-charuco-video")
    ref = tomllib.loads((root / "video" / "camera_array.toml").read_text())["cameras"]
    t0 = pose(ref["0"]["rotation"], ref["0"]["translation"])
    print("| camera | fx robocal / caliscope (std) | fy | cx | cy | rms px robocal / caliscope | baseline m robocal / caliscope | rotation diff deg | frames |")
    print("|---|---|---|---|---|---|---|---|---|")
    for k, cam in enumerate(rig["cameras"]):
        c = cam["calibration"]["camera"]
        std = cam["calibration"].get("std") or {}
        r = ref[str(k)]
        m = r["matrix"]
        cells = []
        for key, val in (("fx", m[0][0]), ("fy", m[1][1]), ("cx", m[0][2]), ("cy", m[1][2])):
            cells.append(f"{c[key]:.1f} / {val:.1f} ({std.get(key, float('nan')):.1f})")
        ours = np.array(cam["camera_from_rig"]["matrix_row_major"], float)
        theirs = pose(r["rotation"], r["translation"]) @ np.linalg.inv(t0)
        base = (np.linalg.norm(ours[:3, 3]), np.linalg.norm(theirs[:3, 3]))
        rot = angle_deg(ours[:3, :3] @ theirs[:3, :3].T)
        print(f"| {cam['name']} | " + " | ".join(cells)
              + f" | {cam['rms_px']:.3f} / {r['error']:.3f} | {base[0]:.3f} / {base[1]:.3f} | {rot:.1f} | {len(cam['frames_seen'])} |")
    print(f"\nrig rms {rig['rms_px']:.3f} px over {len(rig['frames'])} frames")


if __name__ == "__main__":
    main()
