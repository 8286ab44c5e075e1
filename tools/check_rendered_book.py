"""Rendered-page check of the built book in headless Chromium.

Opens every page listed in the book's ``_toc.yml`` from ``book/_build/html`` (file:// URLs,
all network requests blocked) with the system's Chromium driven by selenium, and fails
(exit status 1) when a page

* is missing or does not load (no article),
* shows a broken image (not decoded: ``naturalWidth == 0``), a blank one (a single colour),
  or fewer figures than expected,
* lacks its ledger table (``table.passmd-ledger`` with at least one row) where expected,
* shows an execution error or stderr output (myst-nb ``.output.traceback`` / ``.output.stderr``
  blocks, or a Python traceback anywhere in the text),
* leaves math unrendered (a ``.math`` element without MathJax output, a MathJax error, raw
  ``$$``/``\\(``/``\\[`` in the text) or a web font that failed to load,
* leaves MyST unrendered: a role or directive name in braces (``{download}``, ``{glue:md}``, …)
  or a code fence (`````) in the text,
* shows a code block glued as inline text (an inline ``code`` element that starts with a
  language name and whose lines' first word repeats, ``bash passmd … passmd …``, or that holds
  a shell line continuation),
* is written for a designer (``passmd-audience: designer`` meta tag) and shows a code cell that
  imports an internal module: its visible code uses only the public API (``import passmd``,
  ``from passmd import …``) and the command line,
* shows a number the build could not compute or a unit written wrongly (:data:`TEXT_DEFECTS`): a
  ``nan`` or ``inf`` in the text, ``NaN`` in a table, a unit written twice (``0.1 N N``, ``130 kHz
  kHz``), a dimensionless ratio with a unit (``ζ = 0.05 kg/s``),
* is built on a profile coarser than the paper's and states verdicts, but lacks the note saying how
  much of the paper's grids it lacks (``passmd-expect`` ``partial=1``; ``.passmd-partial-grid``),
* links to a local file that is not in the built book (e.g. a figure's CSV data),
* tries to load anything from the network (the book must display offline),
* scrolls horizontally in a window :data:`WINDOW_WIDTH` px wide (content wider than the window),
* shows a display equation (``mjx-container[display="true"]``), figure or table that does not
  fit the content column (the article's content box) in that window: drawn past the column, cut
  off by a box that hides overflow, or scrolling sideways in its box (``scrollWidth >
  clientWidth``). The page-width rule misses these: a clipped or internally scrolling block
  leaves the page's width intact.

What a page must show comes from its ``passmd-expect`` meta tag (``"figures=2 ledger=1"``),
which the book's extension (``book/_ext/passmd_book.py``) generates from the figure table and the
ledger; pages without it must have at least one figure and one ledger table. A full-page
screenshot of every page is saved: the page laid out in a window of :data:`WINDOW_WIDTH` px, as
tall as the page, so the picture is what a reader scrolling down that window sees (no horizontal
shift, nothing cut at the edges).

Usage: ``python tools/check_rendered_book.py book/_build/html --toc book/_toc.yml
--screenshots artifacts/screenshots`` (``nox -s book_check`` runs this).
"""

from __future__ import annotations

import argparse
import base64
import json
import re
import shutil
import sys
import tempfile
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1280,1000",
    # overlay scrollbars: the window and the full-page screenshot lay the page out at the
    # same width (a classic scrollbar takes 15 px from the window but not from the capture)
    "--hide-scrollbars",
)
#: Width and height (CSS px) of the window pages are laid out in, set exactly through the
#: DevTools protocol (the --window-size of headless Chromium does not fix the viewport).
WINDOW_WIDTH = 1280
WINDOW_HEIGHT = 1000
#: What a page must show when it has no ``passmd-expect`` meta tag.
DEFAULT_EXPECT = {"figures": 1, "ledger": 1, "partial": 0}
#: Units the book writes (a unit repeated after itself is a defect).
UNITS = ("nm", "µm", "mm", "m", "µs", "us", "ms", "s", "ns", "Hz", "kHz", "MHz", "N", "mN", "N/m", "Pa",
         "MPa", "GPa", "kg", "g", "mg", "µg", "kg/s", "m/s", "mm/s", "m/s²", "V", "V/µs", "%", "°")
_UNIT = "|".join(re.escape(u) for u in sorted(UNITS, key=len, reverse=True))
_NUMBER = r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?!\w|\.\d)"
#: Patterns of the visible text (outside code) that are defects, with what each means.
TEXT_DEFECTS = (
    (re.compile(r"(?<![\w.\-])-?(?:nan|inf)(?![\w])"), "a number the build could not compute"),
    (re.compile(rf"(?<![\w/²])({_UNIT})\s+\1(?![\w/²])"), "a unit written twice"),
    (re.compile(rf"[ζμν]\s*=\s*[-+]?[\d.]+(?:e[-+]?\d+)?\s*(?:{_UNIT})(?![\w/²])"),
     "a dimensionless quantity given a unit"),
    # A comparison or margin whose number carries no unit: "1 vs 1", "tolerance 1)", "deviation 133.8
    # exceeds" (the ledger writes every value with its unit, or with what it counts).
    (re.compile(rf"{_NUMBER}\s+vs\b"
                rf"|\b(?:tolerance|deviation)\s+{_NUMBER}(?=\s*(?:[;,.)]|$|exceeds|within))"),
     "a margin without its unit"),
)
#: Table cells that are defects: pandas' missing value.
CELL_DEFECTS = ((re.compile(r"^\s*-?(?:NaN|nan|inf|<NA>|None)\s*$"),
                 "a table cell the build could not compute"),)
LEDGER_SELECTOR = "table.passmd-ledger"
MAX_SCREENSHOT_HEIGHT = 30000  # px; Chromium refuses larger captures

# Runs in the page: waits for MathJax and image decoding, then reports what is shown.
PAGE_FACTS_JS = r"""
const done = arguments[arguments.length - 1];
const ledgerSelector = arguments[0];
(async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    try { await MathJax.startup.promise; } catch (e) {}
  }
  const article = document.querySelector('article.bd-article') || document.querySelector('main');
  const root = article || document.body;
  const imgs = Array.from(root.querySelectorAll('img'));
  await Promise.all(imgs.map(img => img.decode().catch(() => null)));
  try { await document.fonts.ready; } catch (e) {}
  const skip = 'pre, code, script, style, textarea, mjx-container, .highlight, .MathJax';
  const walker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  const rawTex = [];
  for (let node = walker.nextNode(); node; node = walker.nextNode()) {
    if (node.parentElement && node.parentElement.closest(skip)) continue;
    const t = node.textContent;
    for (const token of ['$$', '\\(', '\\[', '\\begin{', '\\frac']) {
      if (t.includes(token)) { rawTex.push(t.trim().slice(0, 80)); break; }
    }
  }
  // Display equations, figures and tables that do not fit the content column (the article's
  // content box): reaching past it, scrolling sideways, or cut off by a box that hides overflow.
  const overflowing = (root) => {
    const style = getComputedStyle(root);
    const box = root.getBoundingClientRect();
    const colLeft = box.left + parseFloat(style.paddingLeft) + parseFloat(style.borderLeftWidth);
    const colRight = box.right - parseFloat(style.paddingRight) - parseFloat(style.borderRightWidth);
    const tex = new Map();  // mjx-container -> its TeX source, to name the equation
    try {
      for (const item of MathJax.startup.document.math) tex.set(item.typesetRoot, item.math);
    } catch (e) {}
    const named = (kind, el) => {
      if (kind === 'equation') {
        const src = tex.get(el) || el.textContent;
        return src.replace(/\s+/g, ' ').trim().slice(0, 70);
      }
      if (kind === 'figure') {
        const img = el.tagName === 'IMG' ? el : el.querySelector('img');
        return ((img && img.getAttribute('src')) || el.textContent.trim()).slice(0, 70);
      }
      const caption = el.querySelector('caption, thead, tr');
      return (caption ? caption.innerText : el.innerText).replace(/\s+/g, ' ').trim().slice(0, 70);
    };
    const items = [
      ...Array.from(root.querySelectorAll('mjx-container[display="true"]')).map(e => ['equation', e]),
      ...Array.from(root.querySelectorAll('figure, img:not(figure img)')).map(e => ['figure', e]),
      ...Array.from(root.querySelectorAll('table')).map(e => ['table', e]),
    ];
    const found = [];
    for (const [kind, el] of items) {
      if (el.getClientRects().length === 0) continue;  // not displayed (e.g. a collapsed block)
      // what is drawn: the element and its typeset math or images (they may overhang it)
      const inner = {equation: ':scope > mjx-math', figure: 'img', table: null}[kind];
      const drawn = [el, ...(inner ? el.querySelectorAll(inner) : [])];
      const rects = drawn.map(e => e.getBoundingClientRect());
      const left = Math.min(...rects.map(r => r.left));
      let right = Math.max(...rects.map(r => r.right));
      if (getComputedStyle(el).overflowX === 'visible') {  // content overflowing the element is drawn
        right = Math.max(right, rects[0].left + el.clientLeft + el.scrollWidth);
      }
      const fact = {
        kind, what: named(kind, el), width: Math.round(right - left),
        column: Math.round(colRight - colLeft),
        past_column: Math.round(Math.max(colLeft - left, right - colRight)),
        scroll_width: 0, box_width: 0,
      };
      // the element scrolls itself, or a box around it (inside the article) scrolls or clips it
      const boxes = [el];
      for (let a = el.parentElement; a && a !== root.parentElement; a = a.parentElement) boxes.push(a);
      for (const b of boxes) {
        if (b.scrollWidth <= b.clientWidth + 1 || getComputedStyle(b).overflowX === 'visible') continue;
        const r = b.getBoundingClientRect();
        const visibleLeft = r.left + b.clientLeft;
        if (b === el || left < visibleLeft - 1 || right > visibleLeft + b.clientWidth + 1) {
          fact.scroll_width = b.scrollWidth;
          fact.box_width = b.clientWidth;
          break;
        }
      }
      if (fact.past_column > 1 || fact.scroll_width) found.push(fact);
    }
    return found;
  };
  // MyST the build left unrendered, and code blocks glued as inline text (a glued fence)
  const rawMyst = [];
  const names = ['download', 'glue(:\\w+)?', 'doc', 'ref', 'numref', 'eq', 'math', 'term', 'code-cell',
                 'literalinclude', 'figure', 'image', 'note', 'warning', 'admonition', 'list-table',
                 'dropdown', 'tab-set'];
  const roles = new RegExp('\\{(' + names.join('|') + ')\\}|```');
  const textWalker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  for (let node = textWalker.nextNode(); node; node = textWalker.nextNode()) {
    const skipped = 'pre, code, script, style, textarea, .highlight';
    if (node.parentElement && node.parentElement.closest(skipped)) continue;
    const m = node.textContent.match(roles);
    if (m) rawMyst.push(node.textContent.trim().slice(0, 80));
  }
  // a fence glued inline: its language name, then lines whose first word repeats (passmd … passmd …),
  // or a shell line continuation; a one-line command in code font (python bench.py --x) is neither
  const lexers = /^(bash|sh|shell|console|python|ipython3?|toml|yaml|json|text)\s+(\S+)\s+(.*)$/;
  const glued = (t) => {
    const m = t.match(lexers);
    return / \\ /.test(t) || (m !== null && t.length > 40 && m[3].split(' ').includes(m[2]));
  };
  const inlineBlocks = Array.from(root.querySelectorAll('code'))
    .filter(c => !c.closest('pre, .highlight'))
    .map(c => c.textContent.replace(/\s+/g, ' ').trim())
    .filter(glued)
    .map(t => t.slice(0, 80));
  const cellImports = Array.from(root.querySelectorAll('.cell_input pre, .cell_input .highlight'))
    .flatMap(c => c.textContent.split('\n'))
    .filter(line => /^\s*(from\s+passmd\.[\w.]+\s+import\b|import\s+passmd\.)/.test(line))
    .map(line => line.trim().slice(0, 80));
  const maths = Array.from(root.querySelectorAll('.math'));
  const text = root.innerText || '';
  // the visible text outside code, and every table cell, for the text-defect patterns
  const prose = [];
  const proseWalker = document.createTreeWalker(root, NodeFilter.SHOW_TEXT);
  for (let node = proseWalker.nextNode(); node; node = proseWalker.nextNode()) {
    // code, and the API reference's entries (signatures and docstrings document code's values)
    const code = 'pre, code, script, style, textarea, .highlight, mjx-container, dl.py';
    if (node.parentElement && node.parentElement.closest(code)) continue;
    prose.push(node.textContent);
  }
  const note = root.querySelector('.passmd-partial-grid');
  done({
    title: document.title,
    has_article: !!article,
    expect: (document.querySelector('meta[name="passmd-expect"]') || {}).content || null,
    audience: (document.querySelector('meta[name="passmd-audience"]') || {}).content || null,
    raw_myst: Array.from(new Set(rawMyst)).slice(0, 5),
    inline_blocks: inlineBlocks.slice(0, 5),
    internal_imports: Array.from(new Set(cellImports)).slice(0, 5),
    images: imgs.map(img => ({
      src: img.getAttribute('src'),
      ok: img.complete && img.naturalWidth > 0 && img.naturalHeight > 0,
      width: img.naturalWidth,
    })),
    error_outputs: Array.from(root.querySelectorAll('.output.traceback, .output.error'))
      .map(e => e.innerText.trim().split('\n').slice(-1)[0].slice(0, 160)),
    stderr_outputs: Array.from(root.querySelectorAll('.output.stderr'))
      .map(e => e.innerText.trim().slice(0, 160)),
    traceback_in_text: text.includes('Traceback (most recent call last)'),
    math_total: maths.length,
    math_rendered: maths.filter(m => m.querySelector('mjx-container')).length,
    math_errors: Array.from(root.querySelectorAll('mjx-merror'))
      .map(e => (e.getAttribute('data-mjx-error') || e.textContent).slice(0, 120)),
    mathjax_loaded: !!(window.MathJax && MathJax.startup),
    raw_tex: rawTex.slice(0, 5),
    visible_text: prose.join(' '),
    table_cells: Array.from(root.querySelectorAll('td')).map(td => td.innerText),
    partial_grid: note ? note.innerText : null,
    ledger_tables: Array.from(root.querySelectorAll(ledgerSelector))
      .filter(t => t.querySelectorAll('tbody tr').length > 0).length,
    overflow: overflowing(root),
    links: Array.from(root.querySelectorAll('a[href]')).map(a => a.getAttribute('href')),
    window_width: window.innerWidth,
    viewport_width: document.documentElement.clientWidth,
    page_width: Math.max(document.documentElement.scrollWidth, document.body ? document.body.scrollWidth : 0),
    fonts_failed: Array.from(document.fonts).filter(f => f.status === 'error').map(f => f.family),
    external_resources: performance.getEntriesByType('resource').map(e => e.name)
      .filter(n => !/^(file|data|blob|about):/.test(n)),
  });
})();
"""


def toc_pages(toc_file: str | Path) -> list[str]:
    """Document names (no extension) of every page in a Jupyter Book ``_toc.yml``, in order."""
    import yaml

    toc = yaml.safe_load(Path(toc_file).read_text(encoding="utf-8"))
    pages: list[str] = []

    def walk(entries):
        for entry in entries or []:
            if "file" in entry:
                pages.append(str(Path(entry["file"]).with_suffix("")))
            for key in ("parts", "chapters", "sections"):
                walk(entry.get(key))

    pages.append(str(Path(toc["root"]).with_suffix("")))
    walk(toc.get("parts"))
    walk(toc.get("chapters"))
    walk(toc.get("sections"))
    return pages


def parse_expect(content: str | None) -> dict[str, int]:
    """Parse a ``passmd-expect`` meta value such as ``"figures=2 ledger=0 partial=1"``.

    ``None`` gives :data:`DEFAULT_EXPECT`. Keys: ``figures`` (minimum number of decoded
    images), ``ledger`` (minimum number of ledger tables) and ``partial`` (1: the page must carry the
    partial-grid note).
    """
    expect = dict(DEFAULT_EXPECT)
    if content is None:
        return expect
    for item in content.split():
        key, sep, value = item.partition("=")
        if not sep or key not in DEFAULT_EXPECT or not value.isdigit():
            raise ValueError(
                f"passmd-expect = {content!r} is not allowed: must be "
                "'figures=<n> ledger=<n> [partial=<0|1>]'"
            )
        expect[key] = int(value)
    return expect


def text_defects(text: str, cells=()) -> list[str]:
    """Each defect :data:`TEXT_DEFECTS` finds in a page's visible text (outside code) and
    :data:`CELL_DEFECTS` in its table cells, with its context."""
    found = []
    for pattern, meaning in TEXT_DEFECTS:
        for match in pattern.finditer(text):
            context = " ".join(text[max(0, match.start() - 40):match.end() + 20].split())
            found.append(f"{meaning}: {match.group(0)!r} in {context!r}")
    for cell in cells:
        for pattern, meaning in CELL_DEFECTS:
            if pattern.search(cell):
                found.append(f"{meaning}: {cell.strip()!r}")
    return found


#: What the partial-grid note must say: per figure, what it computes of the paper profile's points, or
#: that no grid is coarser.
_PARTIAL_NOTE = re.compile(r"\d+ of the paper profile's \d+ (?:grid )?points|None of the grids")


def page_problems(facts: dict) -> list[str]:
    """Everything wrong with one rendered page, from the facts ``PAGE_FACTS_JS`` collected."""
    problems: list[str] = []
    if not facts.get("has_article"):
        problems.append("page did not load: no article element")
    try:
        expect = parse_expect(facts.get("expect"))
    except ValueError as err:
        problems.append(str(err))
        expect = dict(DEFAULT_EXPECT)
    images = facts.get("images", [])
    broken = [img["src"] for img in images if not img["ok"]]
    for src in broken:
        problems.append(f"broken image (not decoded): {src}")
    for src in facts.get("blank_images", []):
        problems.append(f"blank image (a single colour): {src}")
    shown = len(images) - len(broken) - len(facts.get("blank_images", []))
    if shown < expect["figures"]:
        problems.append(f"{shown} figure(s) shown, expected at least {expect['figures']}")
    if facts.get("ledger_tables", 0) < expect["ledger"]:
        problems.append(
            f"{facts.get('ledger_tables', 0)} ledger table(s) ({LEDGER_SELECTOR} with rows), "
            f"expected at least {expect['ledger']}"
        )
    for item in facts.get("overflow", []):
        what = f"{item['kind']} {item['what']!r}"
        if item["past_column"] > 1:
            problems.append(
                f"{what} does not fit the content column: {item['width']} px wide, reaching "
                f"{item['past_column']} px past the {item['column']} px column"
            )
        if item["scroll_width"]:
            problems.append(
                f"{what} is cut off or scrolls sideways: {item['scroll_width']} px of content "
                f"in a {item['box_width']} px box"
            )
    for message in facts.get("error_outputs", []):
        problems.append(f"execution error shown: {message}")
    for message in facts.get("stderr_outputs", []):
        problems.append(f"stderr output shown: {message}")
    if facts.get("traceback_in_text") and not facts.get("error_outputs"):
        problems.append("a Python traceback is shown in the page text")
    if facts.get("math_total", 0):
        if not facts.get("mathjax_loaded"):
            problems.append("MathJax did not load")
        missing = facts["math_total"] - facts.get("math_rendered", 0)
        if missing:
            problems.append(f"{missing} of {facts['math_total']} math element(s) not rendered by MathJax")
    for message in facts.get("math_errors", []):
        problems.append(f"MathJax error: {message}")
    for snippet in facts.get("raw_tex", []):
        problems.append(f"raw TeX left in the page: {snippet!r}")
    for defect in facts.get("text_defects", []):
        problems.append(f"text defect, {defect}")
    if expect["partial"] and not _PARTIAL_NOTE.search(facts.get("partial_grid") or ""):
        problems.append("no partial-grid note (.passmd-partial-grid saying what the page lacks of the paper "
                        "profile's grids) on a page of a coarser profile that states verdicts")
    for snippet in facts.get("raw_myst", []):
        problems.append(f"raw MyST left in the page (a role, directive or fence not rendered): {snippet!r}")
    for snippet in facts.get("inline_blocks", []):
        problems.append(f"a code block shown as inline text: {snippet!r}")
    if facts.get("audience") == "designer":
        for line in facts.get("internal_imports", []):
            problems.append(f"a visible code cell of a designer's page imports an internal module (only "
                            f"`import passmd`, `from passmd import ...` and the command line): {line!r}")
    for href in facts.get("broken_links", []):
        problems.append(f"link to a missing file: {href}")
    visible = facts.get("viewport_width") or facts.get("window_width")
    if visible and facts.get("page_width", 0) > visible + 1:
        problems.append(
            f"page scrolls horizontally: content {facts['page_width']} px wide in a "
            f"{facts['window_width']} px window"
        )
    for family in facts.get("fonts_failed", []):
        problems.append(f"web font failed to load: {family}")
    for url in dict.fromkeys(facts.get("external_resources", [])):  # each URL once
        problems.append(f"network resource requested (the book must display offline): {url}")
    for line in facts.get("network_errors", []):
        problems.append(f"network access attempted (the book must display offline): {line}")
    return problems


def blank_images(page: Path, images: list[dict]) -> list[str]:
    """``src`` of the decoded images of a page whose file shows a single colour."""
    from urllib.parse import unquote, urlsplit

    from PIL import Image

    blank = []
    for img in images:
        parts = urlsplit(img["src"] or "")
        if not img["ok"] or parts.scheme or not parts.path:
            continue  # undecoded (reported already) or not a local file
        with Image.open(page.parent / unquote(parts.path)) as picture:
            low, high = picture.convert("L").getextrema()
        if low == high:
            blank.append(img["src"])
    return blank


def broken_links(page: Path, hrefs: list[str]) -> list[str]:
    """Local links of a page (relative paths, no scheme) whose target file does not exist."""
    from urllib.parse import unquote, urlsplit

    broken = []
    for href in hrefs:
        parts = urlsplit(href)
        if parts.scheme or parts.netloc or not parts.path:
            continue  # external, mailto: or a same-page #anchor
        if not (page.parent / unquote(parts.path)).exists():
            broken.append(href)
    return broken


def _driver(user_data_dir: str):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={user_data_dir}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(120)
    driver.set_script_timeout(120)
    # Block every network request: what the book needs must come from the HTML folder.
    driver.execute_cdp_cmd("Network.enable", {})
    blocked = ["http://*", "https://*", "ws://*", "wss://*", "ftp://*"]
    driver.execute_cdp_cmd("Network.setBlockedURLs", {"urls": blocked})
    _set_window(driver, WINDOW_HEIGHT)
    return driver


def _set_window(driver, height: int) -> None:
    """Lay pages out in a window ``WINDOW_WIDTH`` px wide and ``height`` px tall (CSS px)."""
    driver.execute_cdp_cmd(
        "Emulation.setDeviceMetricsOverride",
        {"width": WINDOW_WIDTH, "height": height, "deviceScaleFactor": 1, "mobile": False},
    )


def _screenshot(driver, target: Path) -> None:
    """Save the whole page as a reader of a ``WINDOW_WIDTH`` px window sees it.

    The window is made as tall as the page (up to ``MAX_SCREENSHOT_HEIGHT``) and the
    viewport captured as it is: the page keeps its layout and horizontal position. (A clip
    of the full content size with ``captureBeyondViewport`` re-lays the page out at another
    size, which shifted the picture sideways against what a reader sees.)
    """
    driver.execute_script("window.scrollTo(0, 0);")
    height = driver.execute_script(
        "return Math.max(document.documentElement.scrollHeight, "
        "document.body ? document.body.scrollHeight : 0);"
    )
    _set_window(driver, int(min(max(height, WINDOW_HEIGHT), MAX_SCREENSHOT_HEIGHT)))
    try:
        shot = driver.execute_cdp_cmd(
            "Page.captureScreenshot", {"format": "png", "captureBeyondViewport": False}
        )
    finally:
        _set_window(driver, WINDOW_HEIGHT)
    target.write_bytes(base64.b64decode(shot["data"]))


def check_book(html_dir: str | Path, pages: list[str], screenshots: str | Path | None = None) -> dict:
    """Open each page in headless Chromium; return ``{page: {"facts": ..., "problems": [...]}}``."""
    html_dir = Path(html_dir).resolve()
    shots = Path(screenshots) if screenshots else None
    if shots:
        shots.mkdir(parents=True, exist_ok=True)
    results: dict[str, dict] = {}
    profile = tempfile.mkdtemp(prefix="passmd-chromium-")
    driver = _driver(profile)
    try:
        for page in pages:
            path = html_dir / f"{page}.html"
            if not path.is_file():
                results[page] = {"facts": {}, "problems": [f"page missing: {path}"]}
                continue
            driver.get_log("browser")  # drop messages of earlier pages
            driver.get(path.as_uri())
            facts = driver.execute_async_script(PAGE_FACTS_JS, LEDGER_SELECTOR)
            facts["blank_images"] = blank_images(path, facts["images"])
            facts["text_defects"] = text_defects(facts.pop("visible_text", ""), facts.pop("table_cells", []))
            facts["broken_links"] = broken_links(path, facts.pop("links", []))
            facts["network_errors"] = [
                entry["message"][:200]
                for entry in driver.get_log("browser")
                if "ERR_BLOCKED_BY_CLIENT" in entry["message"]
                or "ERR_INTERNET_DISCONNECTED" in entry["message"]
            ]
            if shots:
                _screenshot(driver, shots / f"{page.replace('/', '__')}.png")
            results[page] = {"facts": facts, "problems": page_problems(facts)}
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("html_dir", help="built book, e.g. book/_build/html")
    parser.add_argument("--toc", required=True, help="the book's _toc.yml (which pages to check)")
    parser.add_argument("--screenshots", help="folder for full-page screenshots")
    parser.add_argument("--report", help="write the facts and problems of every page as JSON here")
    args = parser.parse_args(argv)

    results = check_book(args.html_dir, toc_pages(args.toc), args.screenshots)
    failed = 0
    for page, result in results.items():
        facts, problems = result["facts"], result["problems"]
        figures = sum(img["ok"] for img in facts.get("images", [])) - len(facts.get("blank_images", []))
        status = "FAIL" if problems else "ok"
        print(
            f"[{status}] {page}: {figures} figure(s), {facts.get('ledger_tables', 0)} ledger table(s), "
            f"{facts.get('math_rendered', 0)}/{facts.get('math_total', 0)} math rendered"
        )
        for problem in problems:
            print(f"       - {problem}")
        failed += bool(problems)
    if args.report:
        Path(args.report).parent.mkdir(parents=True, exist_ok=True)
        Path(args.report).write_text(json.dumps(results, indent=2), encoding="utf-8")
    print(f"rendered-page check: {len(results) - failed} of {len(results)} page(s) ok")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
