#!/usr/bin/env python3
"""Writes a progressive JPEG with thousands of scans, for benches/bounds.sh.

A progressive JPEG is encoded by OpenCV (benches/.venv, see opencv_venv.py)
from a smooth image (so that its AC scans are a few bytes of end-of-band
runs); then its smallest scan (the SOS segment and its entropy-coded data, up
to the next marker) is repeated until the file has SCANS scans. Every extra
scan can make a decoder walk the whole coefficient buffer again: the
pathological input of issue 17 ("a progressive JPEG with thousands of
scans"), a small file for a large image.

Usage: python3 benches/progressive_jpeg.py OUT.jpg [SIDE_PX] [SCANS]
"""
import sys

from opencv_venv import ensure_venv

ensure_venv()
import cv2  # noqa: E402  (after the venv switch)
import numpy as np  # noqa: E402


def segments(data):
    """(start, end, marker) of each marker segment; SOS segments include their scan data."""
    out, i = [], 2
    while i < len(data):
        assert data[i] == 0xFF, f"no marker at {i}"
        marker = data[i + 1]
        if marker == 0xD9:
            out.append((i, i + 2, marker))
            break
        length = int.from_bytes(data[i + 2:i + 4], "big")
        end = i + 2 + length
        if marker == 0xDA:
            # Entropy-coded data: up to the next marker that is not a stuffed
            # 0xFF00 or a restart marker.
            while not (data[end] == 0xFF and data[end + 1] not in (0x00, *range(0xD0, 0xD8))):
                end += 1
        out.append((i, end, marker))
        i = end
    return out


def main():
    out = sys.argv[1]
    side = int(sys.argv[2]) if len(sys.argv) > 2 else 2000
    scans = int(sys.argv[3]) if len(sys.argv) > 3 else 5000
    ramp = np.linspace(60, 200, side)
    image = ((ramp[None, :] + ramp[:, None]) / 2).astype(np.uint8)
    ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_PROGRESSIVE, 1, cv2.IMWRITE_JPEG_QUALITY, 90])
    assert ok
    data = bytes(buf)
    segs = segments(data)
    sos = [s for s in segs if s[2] == 0xDA]
    small = min(sos, key=lambda s: s[1] - s[0])
    extra = data[small[0]:small[1]] * (scans - len(sos))
    eoi = segs[-1][0]
    with open(out, "wb") as f:
        f.write(data[:eoi] + extra + data[eoi:])
    print(f"{out}: {side}x{side}, {scans} scans ({len(sos)} from the encoder, "
          f"the repeated one {small[1] - small[0]} bytes), {eoi + len(extra) + 2} bytes")


if __name__ == "__main__":
    main()
