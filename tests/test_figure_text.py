"""Figures read at page width: the chapter scripts raise small text to the report's minimum
(``chapters.common.readable``), store each figure's text layout in its PNG, and
``make report-check`` judges it at the width the page shows the figure (overlapping text
included)."""

import json

import matplotlib.pyplot as plt
import PIL.Image

from chapters import common
from docs import report_check


def saved(tmp_path, fig, name="figure.png"):
    path = tmp_path / name
    common.save_figure(fig, path)
    plt.close(fig)
    return path


def layout_of(path):
    with PIL.Image.open(path) as picture:
        return json.loads(picture.text[common.LAYOUT_KEY]), picture.width


def test_small_text_is_raised_to_the_minimum_at_page_width(tmp_path):
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4), layout="tight")
    left.plot([1, 2, 3])
    left.set_title("a title in 5-point type", fontsize=5)
    right.legend(right.plot([3, 2, 1], label="a legend in 4-point type"), ["4 pt"], fontsize=4)
    path = saved(tmp_path, fig)
    layout, width = layout_of(path)
    size, _ = layout["smallest"]
    assert size * common.PAGE_WIDTH_PX / width >= common.MIN_FONT_PX
    assert layout["overlaps"] == []
    page = tmp_path / "page.html"
    assert report_check.check_text(page, [(path.name, common.PAGE_WIDTH_PX)]) == []
    # Shown at a third of the column, the same figure's text is too small to read.
    problems = report_check.check_text(page, [(path.name, common.PAGE_WIDTH_PX / 3)])
    assert len(problems) == 1 and "px high as shown" in problems[0]


def test_text_over_another_panel_is_reported(tmp_path):
    """A label that runs into the panel below it (no layout engine to make room)."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6, 4))
    top.set_xlabel("a label\nfour lines\nhigh runs into\nthe panel below", fontsize=16)
    bottom.imshow([[0, 1], [1, 0]])
    path = saved(tmp_path, fig)
    problems = report_check.check_text(tmp_path / "page.html", [(path.name, 736)])
    assert any("overlapping text" in p and "a label" in p for p in problems), problems


def test_rotated_labels_side_by_side_do_not_count_as_overlapping(tmp_path):
    """Rotated tick labels' upright boxes overlap although the labels do not."""
    fig, ax = plt.subplots(figsize=(6, 3), layout="tight")
    ax.bar(range(8), range(8))
    ax.set_xticks(range(8), [f"a long case name {i}" for i in range(8)], rotation=60,
                  ha="right")
    layout, _ = layout_of(saved(tmp_path, fig))
    assert layout["overlaps"] == []
