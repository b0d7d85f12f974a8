"""Sphinx configuration of the vrlib report.

Numbers quoted in the text come from the result files the chapter scripts wrote: every
``build/results/<chapter>/<name>.json`` is loaded here and offered to the pages as a MyST
substitution named ``<chapter>.<name>`` (for example ``{{ ch02_filters.responses }}``), so
the text can never disagree with the figures.
"""

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

project = "vrlib"
author = "the vrlib developers"
copyright = "2026, the vrlib developers"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax copied into the report (_static/mathjax), so formulas render with no network
    "sphinx-mathjax-offline",
]
myst_enable_extensions = ["dollarmath", "substitution"]
myst_heading_anchors = 3  # links such as derivations.md#the-two-pass-shear
napoleon_google_docstring = False
napoleon_numpy_docstring = True
autodoc_member_order = "bysource"
autodoc_typehints = "none"
exclude_patterns = ["_build"]
# furo: a wide content column for the claim and result tables, readable offline (no fonts
# or scripts fetched from the network).
html_theme = "furo"
html_title = "vrlib report"
# A figure given a width (every figure in the chapters) links to its full-size file.
html_scaled_image_link = True
html_static_path = ["_static"]
html_css_files = ["report.css"]


def _load_results():
    results = {}
    for path in sorted((ROOT / "build" / "results").glob("*/*.json")):
        if path.name.startswith("."):  # a temporary file left by an interrupted write
            continue
        results.setdefault(path.parent.name, {})[path.stem] = json.loads(path.read_text())
    return results


myst_substitutions = _load_results()

# numpydoc types such as "array_like, shape (n, 3)" make napoleon look up "shape", which several
# classes define as a property; those ambiguous look-ups are not broken links.
suppress_warnings = ["ref.python"]


def setup(app):
    # SVG output draws glyphs as paths: no web fonts to load, which browsers may refuse over
    # file://. Set here, after sphinx-mathjax-offline has pointed MathJax at its bundled copy.
    app.config.mathjax_path = "mathjax/tex-svg.js"
