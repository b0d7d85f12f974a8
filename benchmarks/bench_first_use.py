"""The wait on first use (``make bench``): ``vrlib render`` in a fresh process with an empty
numba cache, as on a new machine, for the renders a new user starts with (an analytic field,
a scanner's file with the automatic transfer function, shading, a cubic filter, splatting,
pre-integrated classification), at the command line's default image size (256^2), beside the
same command once the cache holds the kernels (one run each: a cold run takes up to 20 s).
The table gives the render as the command line reports it and the whole command (Python's
start and imports included). The command line's render takes a quick start where it can
(:func:`vrlib.raycast.quick_starts`): the quick start's own kernel, the tent filter unlit
with rays one at a time (:func:`vrlib._kernels.raycast.raycast_quick`), while the kernel with
packets is not in the cache, and a kernel without skipping while the one with it
is not; the bench runs it as a user would, with ``VRLIB_QUICK_START`` left out of the
commands' environment.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _report import markdown, write_record

#: What "first use" means here: the issue's target for a first render, in seconds.
TARGET_SECONDS = 3.0

CASES = [
    ("field, glow (the default)", ["gaussian-blob:32"]),
    ("dense field, glow", ["marschner-lobb:41"]),
    ("int16 .npy, auto transfer", ["{scan}"]),
    ("field, shaded", ["gaussian-blob:32", "--shade"]),
    ("field, Catmull-Rom", ["gaussian-blob:32", "--filter", "catmull-rom"]),
    ("field, splatting", ["gaussian-blob:32", "--method", "splat"]),
    ("field, pre-integrated", ["gaussian-blob:32", "--option", "classification=preintegrated"]),
]


def _scan(folder):
    """A 64^3 int16 volume like a CT scan: a dense block in air, with noise."""
    rng = np.random.default_rng(1)
    data = (rng.random((64, 64, 64)) * 30).astype(np.int16)
    data[20:44, 16:48, 24:40] += 1000
    path = Path(folder) / "scan.npy"
    np.save(path, data)
    return path


def _run(argv, cache, out):
    """``(render seconds as printed, whole command seconds)`` of one ``vrlib render``."""
    env = {key: value for key, value in os.environ.items() if key != "VRLIB_QUICK_START"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "vrlib", "render", *argv, "-o", str(out)],
                          env=env, capture_output=True, text=True, check=True)
    whole = time.perf_counter() - start
    return float(re.search(r" in ([0-9.]+) s", done.stdout).group(1)), whole


def main():
    rows, record = [], {"target_seconds": TARGET_SECONDS, "rows": []}
    with tempfile.TemporaryDirectory() as folder:
        scan = _scan(folder)
        out = Path(folder) / "image.png"
        for name, argv in CASES:
            argv = [a.format(scan=scan) for a in argv]
            cache = Path(folder) / f"cache-{len(record['rows'])}"
            render, whole = _run(argv, cache, out)
            warm = _run(argv, cache, out)
            row = {"case": name, "first_render_s": render, "first_command_s": whole,
                   "warm_render_s": warm[0], "warm_command_s": warm[1]}
            record["rows"].append(row)
            rows.append((name, f"{render:.2f}", f"{whole:.2f}", f"{warm[0]:.3f}",
                         f"{warm[1]:.2f}", "yes" if render <= TARGET_SECONDS else "no"))
    print(markdown(["case", "first render (s)", "first command (s)", "warm render (s)",
                    "warm command (s)", f"render <= {TARGET_SECONDS:g} s"], rows))
    write_record("first_use", record)


if __name__ == "__main__":
    main()
