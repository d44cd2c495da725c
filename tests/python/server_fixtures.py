"""What the Python tests share: a BVH written here and the port a started server logs.

Imported by client_test.py and package_test.py from their own folder (a script's folder is the
first entry of sys.path), and by tests/blender/blender_addon_test.py, so it must not import the
motiondb package or its stubs.
"""
import math
import pathlib
import re
import time


def logged_port(log_path, server, timeout=60, face="port"):
    """The port the server picked for --listen 127.0.0.1:0 (face "http port": for --http
    127.0.0.1:0), read from its log."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        match = re.search(rf"\({face} ([0-9]+)\)", pathlib.Path(log_path).read_text())
        if match:
            return int(match.group(1))
        if server.poll() is not None:
            raise RuntimeError(f"motiondb-server exited with {server.returncode}")
        time.sleep(0.02)
    raise RuntimeError(f"motiondb-server did not report its {face}")


def arm_raise_bvh(frames=90, lift=1.0, phase=0.0):
    """A small 3-joint skeleton raising its arm once: a valid BVH written here."""
    rows = []
    for f in range(frames):
        t = f / (frames - 1)
        angle = lift * 120.0 * math.sin(math.pi * t) ** 2
        rows.append(f"0 90 0 {phase:.3f} 0 0 0 {angle:.4f} 0 {angle / 3:.4f} 0 0")
    return ("HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n"
            " CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
            " JOINT Shoulder\n {\n  OFFSET 10 40 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
            "  JOINT Elbow\n  {\n   OFFSET 25 0 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
            "   End Site\n   {\n    OFFSET 25 0 0\n   }\n  }\n }\n}\n"
            f"MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n" + "\n".join(rows) + "\n")
