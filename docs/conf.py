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
]
myst_enable_extensions = ["dollarmath", "substitution"]
napoleon_google_docstring = False
napoleon_numpy_docstring = True
autodoc_member_order = "bysource"
autodoc_typehints = "none"
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_title = "vrlib report"
html_theme_options = {"description": "Volume reconstruction and parallel rendering, measured"}


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
