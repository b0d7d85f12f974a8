"""Shared plumbing for the chapter scripts: where results go, the size profile, atomic output.

Scripts run as modules from the repository root (``python -m chapters.ch02_filters.fig_x``;
``make all`` does this). ``run_*`` scripts compute and write ``build/results/<chapter>/``;
``fig_*`` and ``tab_*`` scripts read those and write ``figures/<chapter>/``. Every file is
written to a temporary name and renamed, so an interrupted build never leaves a corrupt one.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from vrlib.atomic import atomic_path  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent

#: ``default`` (minutes on 2 cores) or ``full`` (thesis scale), from ``make ... PROFILE=``.
PROFILE = os.environ.get("VRLIB_PROFILE", "default")
if PROFILE not in ("default", "full"):
    raise SystemExit(f"VRLIB_PROFILE must be 'default' or 'full', got {PROFILE!r}")


def by_profile(default, full):
    """The value for the active profile."""
    return full if PROFILE == "full" else default


def _chapter(script):
    return Path(script).resolve().parent.name


def result_path(script, name):
    """``build/results/<chapter of script>/<name>``."""
    return ROOT / "build" / "results" / _chapter(script) / name


def figure_path(script, name):
    """``figures/<chapter of script>/<name>``."""
    return ROOT / "figures" / _chapter(script) / name


def save_figure(fig, path):
    """Save a matplotlib figure atomically (format from the suffix)."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=150, bbox_inches="tight", metadata={"Software": None})


def write_json(path, data):
    """Write ``data`` as indented JSON, atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n")


def read_json(path):
    """Read a JSON result file."""
    return json.loads(Path(path).read_text())


def write_csv(path, header, rows):
    """Write a CSV table with a header row, atomically."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    with atomic_path(path) as tmp:
        tmp.write_text(buffer.getvalue())


def progress(iterable, label, total=None):
    """A progress bar on stderr for a long sweep (tqdm; quiet when stderr is not a terminal
    except for a line at the start and the end)."""
    import sys

    from tqdm import tqdm

    return tqdm(iterable, desc=label, total=total, file=sys.stderr, mininterval=2.0,
                dynamic_ncols=True, disable=None if sys.stderr.isatty() else False)
