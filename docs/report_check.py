"""Check the built report in a real browser: ``python docs/report_check.py build/report/html``.

Every page is rendered by headless Chromium (Debian's ``chromium``) to a PNG screenshot, which
must not be blank; every image a page refers to must exist and decode. Prints one line per
page and exits 1 if any page fails. Screenshots are kept under ``build/report/screenshots``.
"""

import html.parser
import shutil
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

SKIP = {"genindex.html", "search.html", "py-modindex.html"}


class Images(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.sources = []

    def handle_starttag(self, tag, attrs):
        if tag == "img":
            self.sources.append(dict(attrs).get("src", ""))


def browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    raise SystemExit("report-check needs Chromium: apt-get install chromium")


def screenshot(chrome, page, out):
    subprocess.run([chrome, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    "--window-size=1280,2000", f"--screenshot={out}", page.as_uri()],
                   capture_output=True, timeout=120, check=False)
    return out.exists() and out.stat().st_size > 0


def check_page(chrome, page, name, shots):
    problems = []
    parser = Images()
    parser.feed(page.read_text(encoding="utf-8"))
    for src in parser.sources:
        if src.startswith(("http:", "https:", "data:")):
            continue
        target = (page.parent / src.split("#")[0]).resolve()
        if not target.is_file():
            problems.append(f"missing image {src}")
            continue
        try:
            pixels = iio.imread(target, index=0)
        except Exception as error:  # any decoding failure is a broken image
            problems.append(f"broken image {src}: {error}")
            continue
        if pixels.size == 0:
            problems.append(f"empty image {src}")
    out = shots / (name.replace("/", "-").removesuffix(".html") + ".png")
    if not screenshot(chrome, page, out):
        problems.append("the browser made no screenshot")
    else:
        shot = iio.imread(out)[..., :3].astype(float)
        inked = np.mean(np.abs(shot - shot[0, 0]).sum(axis=-1) > 30)
        if inked < 0.01:
            problems.append(f"blank page ({100 * inked:.2f}% of pixels drawn)")
    return len(parser.sources), problems


def main(root):
    root = Path(root).resolve()
    pages = sorted(p for p in root.rglob("*.html") if p.name not in SKIP
                   and "_modules" not in p.parts and "_static" not in p.parts)
    if not pages:
        raise SystemExit(f"no pages under {root}: build the report first (make report)")
    shots = root.parent / "screenshots"
    shots.mkdir(parents=True, exist_ok=True)
    chrome = browser()
    failed = 0
    for page in pages:
        images, problems = check_page(chrome, page, str(page.relative_to(root)), shots)
        status = "ok" if not problems else "FAIL: " + "; ".join(problems)
        failed += bool(problems)
        print(f"{page.relative_to(root)}: {images} images, {status}")
    print(f"{len(pages) - failed} of {len(pages)} pages pass; screenshots in {shots}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "build/report/html"))
