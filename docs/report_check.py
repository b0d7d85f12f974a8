"""Check the built report in a real browser, offline:
``python docs/report_check.py build/report/html``.

Every page is opened by headless Chromium (Debian's ``chromium``) with the network shut off
(every request goes to a closed local proxy), as a reader without a connection would see it.
A page fails when:

- its screenshot is blank, or an image it shows is missing or does not decode;
- it loads a script, style sheet or font from a network address;
- raw TeX shows in its rendered text (``\\(``, ``$$``, ``\\frac`` ... outside code), or MathJax
  reports an error in a formula;
- an image is shown at less than half its own width without a link to the full-size file;
- a table is wider than the text column it sits in;
- a figure's text, at the width the page shows the figure, is smaller than
  :data:`MIN_TEXT_PX` pixels, or a text overlaps another text or another panel (a title cut
  by the image above it, a cell's text spilling into the next): the chapter scripts store
  each figure's text layout in its PNG (``chapters.common.text_layout``).

The layout checks run inside the page: a copy of it with a small probe script is opened and
the probe's findings read back from the rendered DOM (``--dump-dom``). Prints one line per page
and exits 1 if any page fails. Screenshots are kept under ``build/report/screenshots``.
"""

import html.parser
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import PIL.Image

SKIP = {"genindex.html", "search.html", "py-modindex.html"}
#: Smallest font size (CSS pixels) a figure's text may have as the page shows it.
MIN_TEXT_PX = 9.0
LAYOUT_KEY = "vrlib-text-layout"  # chapters.common.LAYOUT_KEY (the report needs no chapters)
WINDOW = (1280, 2000)
OFFLINE = ["--proxy-server=http://127.0.0.1:9", "--proxy-bypass-list=<-loopback>"]
# Long enough for MathJax to typeset the longest page (virtual time: it passes as fast as the
# page lets it).
BUDGET_MS = 20000

# Runs in the page once it has loaded and MathJax (if any) has typeset; writes its findings
# as JSON into a <pre id="vrlib-probe">.
PROBE = r"""
<script>
window.addEventListener("load", async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    try { await MathJax.startup.promise; } catch (e) {}
  }
  const out = {tex: [], mathErrors: 0, images: [], tables: [], shown: [],
               mathjax: !!(window.MathJax && MathJax.version)};
  const commands = "frac|mathrm|mathbf|sum|int|sqrt|sigma|alpha|omega|le|ge|cdot|times|text";
  const raw = new RegExp(String.raw`\\\(|\\\)|\\\[|\\\]|\$\$|\\(${commands})\b|` +
                         String.raw`\$[^$\s][^$]*[^$\s\\]\$`);
  const code = "pre, code, script, style, mjx-container, .highlight, textarea, #vrlib-probe";
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    const parent = node.parentElement;
    if (!parent || parent.closest(code) || !parent.getClientRects().length) continue;
    const text = node.textContent;
    if (raw.test(text)) out.tex.push(text.trim().slice(0, 80));
  }
  out.mathErrors = document.querySelectorAll("mjx-merror, .MathJax_Error").length;
  const column = document.querySelector("article") || document.querySelector("[role=main]") ||
                 document.body;
  for (const img of column.querySelectorAll("img")) {
    const shown = img.getBoundingClientRect().width;
    out.shown.push([img.getAttribute("src"), shown]);
    if (img.naturalWidth > 0 && shown < img.naturalWidth / 2 && !img.closest("a[href]")) {
      const size = `${Math.round(shown)} of ${img.naturalWidth} px`;
      out.images.push(`${img.getAttribute("src")} (${size})`);
    }
  }
  for (const table of column.querySelectorAll("table")) {
    // furo wraps each table in a padded scrolling container: a table wider than the column,
    // or one its container has to scroll, does not fit.
    const box = table.getBoundingClientRect();
    const scroller = table.closest(".table-wrapper");
    if (box.width > column.clientWidth + 1 ||
        (scroller && scroller.scrollWidth > scroller.clientWidth + 1)) {
      const caption = table.querySelector("caption");
      out.tables.push(`${caption ? caption.textContent.trim().slice(0, 60) : "a table"} ` +
                      `(${Math.round(box.width)} px in a ${column.clientWidth} px column)`);
    }
  }
  const pre = document.createElement("pre");
  pre.id = "vrlib-probe";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>
"""


class Resources(html.parser.HTMLParser):
    """The images a page shows and the network addresses it loads from."""

    def __init__(self):
        super().__init__()
        self.images, self.remote = [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        source = attrs.get("src") if tag in ("script", "img") else (
            attrs.get("href") if tag == "link" else None)
        if source and re.match(r"(https?:)?//", source):
            self.remote.append(source)


def browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    raise SystemExit("report-check needs Chromium: apt-get install chromium")


def chrome_run(chrome, *args):
    return subprocess.run([chrome, "--headless", "--no-sandbox", "--disable-gpu",
                           "--hide-scrollbars", f"--window-size={WINDOW[0]},{WINDOW[1]}",
                           f"--virtual-time-budget={BUDGET_MS}", *OFFLINE, *args],
                          capture_output=True, text=True, timeout=180, check=False)


def probe(chrome, page):
    """What the probe script found on ``page`` (None if the browser gave no answer)."""
    copy = page.with_name(f".probe-{page.name}")
    text = page.read_text(encoding="utf-8")
    copy.write_text(text.replace("</body>", PROBE + "</body>", 1), encoding="utf-8")
    try:
        dom = chrome_run(chrome, "--dump-dom", copy.as_uri()).stdout
    finally:
        copy.unlink()
    found = re.search(r'<pre id="vrlib-probe">(.*?)</pre>', dom, flags=re.S)
    if not found:
        return None
    return json.loads(html.unescape(found.group(1)))


def check_images(page, sources):
    problems = []
    for src in sources:
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
    return problems


def check_text(page, shown):
    """Problems of the figures' text as the page shows them (``shown``: ``[src, width]``)."""
    problems = []
    for src, width in shown:
        target = (page.parent / src.split("#")[0]).resolve()
        if target.suffix != ".png" or not target.is_file() or width <= 0:
            continue
        with PIL.Image.open(target) as picture:
            layout = picture.text.get(LAYOUT_KEY)
            natural = picture.width
        if layout is None:
            continue
        layout = json.loads(layout)
        size, text = layout["smallest"]
        if size is not None and size * width / natural < MIN_TEXT_PX:
            problems.append(f"{target.name}: text {text!r} is {size * width / natural:.1f} px "
                            f"high as shown (at least {MIN_TEXT_PX:g})")
        if layout["overlaps"]:
            problems.append(f"{target.name}: overlapping text: {layout['overlaps'][:2]}")
    return problems


def check_page(chrome, page, name, shots):
    resources = Resources()
    resources.feed(page.read_text(encoding="utf-8"))
    problems = check_images(page, resources.images)
    problems += [f"loads {url} from the network" for url in resources.remote]
    found = probe(chrome, page)
    if found is None:
        problems.append("the browser returned no layout probe")
    else:
        if found["tex"]:
            problems.append(f"raw TeX in the text: {found['tex'][:3]}")
        if found["mathErrors"]:
            problems.append(f"{found['mathErrors']} formula(s) MathJax could not typeset")
        if found["images"]:
            problems.append(f"image shown at under half its width with no link: {found['images']}")
        if found["tables"]:
            problems.append(f"table wider than the text column: {found['tables']}")
        problems += check_text(page, found["shown"])
    out = shots / (name.replace("/", "-").removesuffix(".html") + ".png")
    out.unlink(missing_ok=True)
    chrome_run(chrome, f"--screenshot={out}", page.as_uri())
    if not (out.exists() and out.stat().st_size > 0):
        problems.append("the browser made no screenshot")
    else:
        shot = iio.imread(out)[..., :3].astype(float)
        inked = np.mean(np.abs(shot - shot[0, 0]).sum(axis=-1) > 30)
        if inked < 0.01:
            problems.append(f"blank page ({100 * inked:.2f}% of pixels drawn)")
    return len(resources.images), problems


def main(root):
    root = Path(root).resolve()
    pages = sorted(p for p in root.rglob("*.html") if p.name not in SKIP
                   and not p.name.startswith(".")
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
        print(f"{page.relative_to(root)}: {images} images, {status}", flush=True)
    print(f"{len(pages) - failed} of {len(pages)} pages pass (offline, "
          f"{WINDOW[0]}x{WINDOW[1]} window); screenshots in {shots}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "build/report/html"))
