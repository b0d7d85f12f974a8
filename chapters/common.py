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
import matplotlib.text  # noqa: E402

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


#: Resolution figures are saved at.
DPI = 150
#: PNG text key under which a figure's text layout (:func:`text_layout`) is stored, for
#: ``make report-check`` to judge at the width the page shows it.
LAYOUT_KEY = "vrlib-text-layout"


#: Width (CSS pixels) of the report's text column, where a full-width figure is shown, and
#: the smallest font size (CSS pixels) a figure's text may have there.
PAGE_WIDTH_PX = 736
MIN_FONT_PX = 9.0


def save_figure(fig, path):
    """Save a matplotlib figure atomically (format from the suffix), with no text smaller than
    :data:`MIN_FONT_PX` at the report's column width (:func:`readable`); a PNG carries its
    text layout (:func:`text_layout`) in its metadata."""
    readable(fig)
    metadata = {"Software": None}
    if Path(path).suffix == ".png":
        metadata[LAYOUT_KEY] = json.dumps(text_layout(fig))
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=DPI, bbox_inches="tight", metadata=metadata)


def readable(fig, margin=1.1):
    """Raise every text that a full-width figure would show below :data:`MIN_FONT_PX` (with
    ``margin``) to that size. The figure's layout engine (``layout="tight"`` or
    ``"constrained"``) then makes room for it when the figure is saved.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots(figsize=(10, 3), layout="tight")
    >>> _ = ax.set_title("small", fontsize=5)
    >>> readable(fig)
    >>> ax.title.get_fontsize() > 5                # at least 9.9 px in a 736 px column
    True
    >>> plt.close(fig)
    """
    for _ in range(3):  # larger text widens the saved figure: again until none is too small
        renderer, drawn = _draw(fig)
        width = fig.get_tightbbox(renderer).width + 0.2  # inches, as saved (with padding)
        smallest = margin * MIN_FONT_PX * 72.0 * width / PAGE_WIDTH_PX  # points
        small = [text for text in drawn if text.get_fontsize() < smallest]
        if not small:
            return
        for text in small:
            text.set_fontsize(smallest)
        for axes in fig.axes:  # tick labels made at the next draw take the axis's size
            for axis in (axes.xaxis, axes.yaxis):
                ticks = axis.get_major_ticks()
                if ticks and ticks[0].label1.get_fontsize() < smallest:
                    axis.set_tick_params(which="both", labelsize=smallest)


def _draw(fig):
    """Draw ``fig``; returns the renderer and the texts it drew that show something (an axis
    keeps tick labels it does not draw, which :meth:`Figure.findobj` would also find)."""
    renderer = fig.canvas.get_renderer()
    drawn = []
    draw = matplotlib.text.Text.draw

    def recorded(text, renderer):
        draw(text, renderer)
        drawn.append(text)

    matplotlib.text.Text.draw = recorded
    try:
        fig.draw(renderer)
    finally:
        matplotlib.text.Text.draw = draw
    return renderer, [text for text in drawn if text.get_text().strip()
                      and text.get_visible() and text.get_alpha() != 0]


def text_layout(fig):
    """What a reader needs of a figure's text: the saved image's width in pixels, its
    smallest text (font size in the image's pixels, and the text), and every pair of texts,
    or text and another panel, that overlap (one hides part of the other).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> fig, (a, b) = plt.subplots(2, 1, figsize=(3, 2))
    >>> _ = a.set_xlabel("a long label that runs into the panel below", fontsize=14)
    >>> layout = text_layout(fig)
    >>> layout["smallest"][0] < 14 * DPI / 72
    True
    >>> [o for o in layout["overlaps"] if o.startswith("'a long")]
    ["'a long label that runs into th' over the panel ''"]
    >>> plt.close(fig)
    """
    renderer, drawn = _draw(fig)
    texts = []
    for text in drawn:
        label = text.get_text().strip()
        box = text.get_window_extent(renderer)
        if box.width <= 0 or box.height <= 0:
            continue
        upright = text.get_rotation() % 90.0 == 0.0  # else its box is far larger than it
        texts.append((label, text.get_fontsize() * DPI / 72.0, box, text.axes, upright))
    overlaps = []
    for i, (label, _, box, axes, upright) in enumerate(texts):
        for other, _, other_box, _, other_upright in texts[i + 1:]:
            if upright and other_upright and _overlap(box, other_box) > 0.15:
                overlaps.append(f"{label[:30]!r} over {other[:30]!r}")
        for panel in fig.axes:
            if panel is axes or not _shows_something(panel):
                continue
            if _overlap(box, panel.get_window_extent(renderer)) > 0.15:
                overlaps.append(f"{label[:30]!r} over the panel {panel.get_title()[:30]!r}")
    tight = fig.get_tightbbox(renderer)
    smallest = min(((size, label) for label, size, *_ in texts), default=(None, ""))
    return {"width": round((tight.width + 0.2) * DPI), "smallest": [smallest[0],
                                                                   smallest[1][:40]],
            "overlaps": overlaps}


def _shows_something(panel):
    """Whether a panel draws anything a text over it would hide (an empty frame does not)."""
    return panel.get_visible() and bool(panel.axison or panel.images or panel.lines
                                        or panel.collections or panel.patches)


def _overlap(box, other):
    """Share of ``box``'s area that ``other`` covers."""
    width = min(box.x1, other.x1) - max(box.x0, other.x0)
    height = min(box.y1, other.y1) - max(box.y0, other.y0)
    if width <= 0 or height <= 0:
        return 0.0
    return width * height / (box.width * box.height)


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
