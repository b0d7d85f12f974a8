"""``make report-check`` catches the faults a reader sees offline: raw TeX, images shrunk
below half their width with no link to the full-size file, tables wider than the column,
network loads, missing images. Runs where Chromium is installed (``make report-check``
installs it; CI's test machine may not have it)."""

import shutil

import numpy as np
import pytest

from docs import report_check
from vrlib.image import Image

pytestmark = pytest.mark.skipif(shutil.which("chromium") is None,
                                reason="Chromium is not installed (apt-get install chromium)")

PAGE = """<!DOCTYPE html><html><head><meta charset="utf-8">{head}</head>
<body><article style="width: 600px">{body}</article></body></html>"""


def write_page(folder, body, head=""):
    Image(np.full((600, 1600, 4), 0.5)).save(folder / "wide.png")
    page = folder / "page.html"
    page.write_text(PAGE.format(head=head, body=body), encoding="utf-8")
    return page


def problems_on(page, tmp_path):
    shots = tmp_path / "shots"
    shots.mkdir(exist_ok=True)
    _, problems = report_check.check_page(report_check.browser(), page, "page.html", shots)
    return problems


def test_a_clean_page_passes(tmp_path):
    body = ("<p>Text, and a figure linked to its full size:</p>"
            '<a href="wide.png"><img src="wide.png" style="width: 100%"></a>'
            "<table><tr><td>a</td><td>narrow table</td></tr></table>")
    assert problems_on(write_page(tmp_path, body), tmp_path) == []


FAULTS = {
    "raw TeX": r"<p>The error falls as \(h^4\) with the step.</p>",
    "under half its width": '<img src="wide.png" style="width: 100%">',
    "wider than the text column": "<table><tr><td>" + "x" * 200 + "</td></tr></table>",
    "missing image": '<img src="missing.png">',
}


def test_each_fault_is_reported(tmp_path):
    """One page with every fault (one browser run): each is named."""
    head = '<script src="https://cdn.example.org/mathjax.js"></script>'
    body = "<p>Where $k \\int F \\approx 1$ the silhouette ends.</p>" + "".join(FAULTS.values())
    problems = problems_on(write_page(tmp_path, body, head), tmp_path)
    for fault in [*FAULTS, "from the network"]:
        assert any(fault in p for p in problems), (fault, problems)
    tex = next(p for p in problems if "raw TeX" in p)
    assert "\\int" in tex and "\\(" in tex


def test_chromium_lookup_names_the_package(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(SystemExit, match="apt-get install chromium"):
        report_check.browser()
