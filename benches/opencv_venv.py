"""The one Python environment of every script that compares robocal with
OpenCV: benches/.venv with the pinned reference (issue 5:
opencv-python-headless 4.14.0.94; the 4.12 wheels are 4-12x slower through
their IPP path and the 5.0 bindings lack calibrateHandEye) plus numpy and
PyYAML.

A script calls `ensure_venv()` before importing cv2: outside the venv it
creates the venv on first use, installs the pinned packages when the venv's
stamp file does not list exactly PINNED, and re-runs the script with the
venv's python (same arguments); inside the venv it returns at once.

    sys.path.insert(0, <this folder>)   # only for scripts outside benches/
    from opencv_venv import ensure_venv
    ensure_venv()
    import cv2
"""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
VENV = os.path.join(HERE, ".venv")
PYTHON = os.path.join(VENV, "bin", "python")
PINNED = ["opencv-python-headless==4.14.0.94", "numpy", "pyyaml"]
# Records what was installed, so that a venv made by an older script (or with
# other pins) gets the current set without running pip on every start.
STAMP = os.path.join(VENV, "robocal-pinned.txt")


def _installed_pins():
    try:
        with open(STAMP) as f:
            return f.read().split()
    except OSError:
        return None


def ensure_venv():
    """Return inside benches/.venv; otherwise create/update it and re-exec."""
    if os.path.abspath(sys.prefix) == os.path.abspath(VENV):
        return
    if not os.path.exists(PYTHON):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
    if _installed_pins() != PINNED:
        subprocess.check_call([PYTHON, "-m", "pip", "install", "-q", *PINNED])
        with open(STAMP, "w") as f:
            f.write("\n".join(PINNED) + "\n")
    script = os.path.abspath(sys.argv[0])
    os.execv(PYTHON, [PYTHON, script, *sys.argv[1:]])
