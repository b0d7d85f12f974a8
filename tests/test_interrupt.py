"""Killing ``make all`` mid-run and running it again gives complete, correct outputs; at no
point is a corrupt result or figure left under its real name (writes go to a temporary name
and are renamed). Slow: it rebuilds everything, so it runs in ``make test-all``."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def complete(path):
    """Whether a result or figure file is whole."""
    data = path.read_bytes()
    if path.suffix == ".json":
        json.loads(data)
        return True
    if path.suffix == ".png":
        return data.startswith(b"\x89PNG") and data.rstrip().endswith(b"IEND\xaeB`\x82")
    if path.suffix == ".csv":
        return data.endswith(b"\n") and b"," in data.splitlines()[0]
    return True


def outputs(clone):
    for folder in ("build/results", "figures"):
        for path in (clone / folder).rglob("*"):
            if path.is_file() and not path.name.startswith("."):
                yield path


@pytest.mark.slow
def test_killed_make_all_recovers(tmp_path):
    if not (ROOT / ".git").exists() or shutil.which("git") is None:
        pytest.skip("needs a git checkout to clone")
    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    # Borrow this environment without reinstalling into it: the Makefile's install marker is
    # pointed at a fresh file, so make sees the environment as up to date.
    (clone / ".venv").symlink_to(Path(sys.executable).parent.parent)
    ready = clone / "build" / "environment-ready"
    ready.parent.mkdir()
    ready.touch()
    make = ["make", "all", f"INSTALLED={ready}"]
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    job = subprocess.Popen(make, cwd=clone, env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, start_new_session=True)
    # Kill the whole job (make and the chapter script it runs) in the middle of the work.
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline and job.poll() is None:
        if len(list(outputs(clone))) >= 6:
            break
        time.sleep(0.5)
    time.sleep(3.0)
    os.killpg(job.pid, signal.SIGKILL)
    job.wait()
    for path in outputs(clone):
        assert complete(path), f"corrupt after the kill: {path}"
    again = subprocess.run(make, cwd=clone, env=env, capture_output=True,
                           text=True, timeout=3000, check=False)
    assert again.returncode == 0, again.stderr[-3000:]
    for path in outputs(clone):
        assert complete(path), f"corrupt after the rerun: {path}"
    assert (clone / "build/report/html/index.html").exists()
    chapters = {p.parent.name for p in (clone / "chapters").glob("ch*/run_*.py")}
    assert chapters <= {p.name for p in (clone / "build/results").iterdir()}
