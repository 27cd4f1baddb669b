"""Open the built book in headless Chromium and check what a reader would see.

Run by ``make test`` after the book is built::

    .venv/bin/python tests/browser/check_book.py [--chromium /usr/bin/chromium] book/_build/html

It is not a pytest module (no ``test_`` prefix), so the unit-test run does not collect it.

For every content page (``intro.html``, the other top-level pages and every ``notebooks/*.html``):

* the static HTML loads at most one MathJax script (exactly one where the page holds math), from
  the book's own ``_static`` (the file exists), and no script or stylesheet from the web;
* Chromium renders the page (``--dump-dom`` after a virtual-time budget) and, where the page holds
  math, every math element contains MathJax output (``<mjx-container>``), with no MathJax error and
  no raw TeX (``\\(``, ``\\[``, ``$$``, ``\\frac``, ...) left in the visible text;
* the intro and "what is simulated" pages hold math at all;
* every notebook page holds at least one ``<table>``, and the Verdicts page one per chapter;
* laid out in a 1280 x 900 window (a script added to a temporary copy of the page measures it):
  no visible table is wider than the text column, or scrolls sideways inside it; no code cell's
  input is visible (the chapters hide their code under "Show code cell source"); and the visible
  text holds no nbval marker (``NBVAL``).

Exits 1 with one line per problem, 0 when every page passes.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

from bs4 import BeautifulSoup

# index.html is a redirect to intro.html written by Jupyter Book; the rest are generated lists.
NOT_CONTENT = {"index.html", "genindex.html", "search.html", "py-modindex.html"}
PAGES_NEEDING_MATH = ("intro.html", "simulated.html")
VERDICTS = "verdicts.html"
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)
# Visible text that is still TeX after MathJax ran: delimiters, or a backslash command.
RAW_TEX = re.compile(r"\\[(\[]|\$\$|\\(?:frac|sum|mathrm|left|right|begin|end|sqrt|lVert|varphi)\b")
# Elements whose text a reader does not see as prose (code is allowed to contain backslashes).
NOT_PROSE = ("script", "style", "pre", "code", "textarea", "svg", "noscript", "template")
WINDOW = "1280,900"
# Measures the laid-out page once it has loaded (and MathJax had time to typeset) and writes the
# result as JSON into <pre id="nctwin-layout">, which --dump-dom then carries out. A table
# overflows if it is wider than the article column or if any box between it and the column
# scrolls sideways; an element is visible if it has a layout box (a closed <details> gives none).
LAYOUT_ID = "nctwin-layout"
LAYOUT_JS = """
<script>
window.addEventListener("load", () => setTimeout(() => {
  const col = document.querySelector("article.bd-article") || document.querySelector("main")
    || document.body;
  const style = getComputedStyle(col);
  const width = col.clientWidth - parseFloat(style.paddingLeft) - parseFloat(style.paddingRight);
  const shown = (el) => !el.closest("details:not([open])") && (el.checkVisibility
    ? el.checkVisibility({visibilityProperty: true}) : el.getClientRects().length > 0);
  const out = {column: width, tables: 0, overflow: [], code: [], nbval: false};
  document.querySelectorAll("table").forEach((t) => {
    if (!shown(t)) return;
    out.tables += 1;
    let box = null;
    for (let e = t.parentElement; e && e !== col.parentElement && !box; e = e.parentElement) {
      if (e.scrollWidth > e.clientWidth + 1 && getComputedStyle(e).overflowX !== "visible") {
        box = e;
      }
    }
    const w = Math.round(t.getBoundingClientRect().width);
    out.column = Math.round(width);
    if (w > width + 1 || box) {
      const head = Array.from(t.querySelectorAll("th")).map((x) => x.textContent.trim())
        .filter((x) => x).slice(0, 3).join(" | ");
      const where = box ? `scrolls in ${box.tagName.toLowerCase()}.${box.classList[0]}`
        + ` (${box.clientWidth} px)` : `column ${width} px`;
      out.overflow.push(`${w} px wide, ${where}: ${head}`.slice(0, 140));
    }
  });
  document.querySelectorAll("div.cell_input").forEach((c) => {
    if (shown(c)) out.code.push(c.textContent.trim().split("\\n")[0].slice(0, 60));
  });
  out.nbval = /NBVAL/.test(document.body.innerText);
  const pre = document.createElement("pre");
  pre.id = "nctwin-layout";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
}, 1000));
</script>
"""


@dataclass
class PageReport:
    page: str
    problems: list[str] = field(default_factory=list)
    math: int = 0
    rendered: int = 0
    tables: int = 0
    column_px: int = 0
    seconds: float = 0.0


def content_pages(html_dir: Path) -> list[Path]:
    """intro.html first, then the other top-level pages, then notebooks/*.html."""
    top = sorted(p for p in html_dir.glob("*.html") if p.name not in NOT_CONTENT)
    top.sort(key=lambda p: p.name != "intro.html")
    return top + sorted((html_dir / "notebooks").glob("*.html"))


def is_remote(url: str | None) -> bool:
    return bool(url) and (url.startswith("//") or urlsplit(url).scheme in ("http", "https"))


def check_static(path: Path, html_dir: Path, report: PageReport) -> None:
    """Checks on the HTML as written by Sphinx, before any script ran."""
    soup = BeautifulSoup(path.read_text(encoding="utf-8"), "html.parser")
    report.math = len(soup.select("span.math, div.math"))
    for tag in soup.find_all("script", src=True):
        if is_remote(tag["src"]):
            report.problems.append(f"loads a script from the web: {tag['src']}")
    for tag in soup.find_all("link", href=True):
        rel = set(tag.get("rel") or ())
        if rel & {"stylesheet", "preload", "modulepreload"} and is_remote(tag["href"]):
            report.problems.append(f"loads {'/'.join(sorted(rel))} from the web: {tag['href']}")
    mathjax = [t["src"] for t in soup.find_all("script", src=True) if "mathjax" in t["src"].lower()]
    # Sphinx loads MathJax only on pages that hold math; more than one copy is always wrong.
    if len(mathjax) > 1 or (report.math and not mathjax):
        report.problems.append(
            f"expected one MathJax <script>, found {len(mathjax)}: {mathjax[:3]}"
        )
    for src in mathjax:
        target = (path.parent / urlsplit(src).path).resolve()
        if is_remote(src):
            continue  # already reported above
        if not target.is_file():
            report.problems.append(f"MathJax script {src} does not resolve to a file ({target})")
        elif html_dir.resolve() not in target.parents:
            report.problems.append(f"MathJax script {src} lies outside the built book")


def render(path: Path, chromium: str, budget_ms: int, timeout_s: int) -> tuple[str | None, str]:
    """The DOM after Chromium ran the page's scripts (and :data:`LAYOUT_JS`), or None and why.

    Chromium opens a copy of the page, beside it so that relative links resolve, with the
    layout script added before ``</body>``; the copy is removed afterwards.
    """
    html = path.read_text(encoding="utf-8")
    at = html.rfind("</body>")
    copy = path.with_name(f".layout-{path.name}")
    copy.write_text(html[:at] + LAYOUT_JS + html[at:], encoding="utf-8")
    profile = tempfile.mkdtemp(prefix="nctwin-chromium-")
    try:
        cmd = [
            "timeout",
            str(timeout_s),
            chromium,
            *CHROMIUM_FLAGS,
            f"--user-data-dir={profile}",
            f"--window-size={WINDOW}",
            "--dump-dom",
            f"--virtual-time-budget={budget_ms}",
            copy.resolve().as_uri(),
        ]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    finally:
        shutil.rmtree(profile, ignore_errors=True)
        copy.unlink(missing_ok=True)
    if proc.returncode != 0 or "<html" not in proc.stdout:
        tail = " | ".join(proc.stderr.strip().splitlines()[-5:])
        why = "timed out" if proc.returncode == 124 else f"exit code {proc.returncode}"
        return None, f"chromium failed ({why}): {tail}"
    return proc.stdout, ""


def visible_text(soup: BeautifulSoup) -> str:
    body = soup.body or soup
    for tag in body.find_all(NOT_PROSE):
        tag.decompose()
    return body.get_text(" ")


def check_layout(soup: BeautifulSoup, report: PageReport) -> None:
    """Checks on what :data:`LAYOUT_JS` measured: tables fit, code hidden, no nbval marker."""
    tag = soup.find(id=LAYOUT_ID)
    if tag is None:
        report.problems.append("the layout script did not run (no measurements in the DOM)")
        return
    layout = json.loads(tag.get_text())
    tag.decompose()
    report.column_px = layout["column"]
    report.problems += [f"table overflows its column: {o}" for o in layout["overflow"]]
    if layout["code"]:
        report.problems.append(
            f"{len(layout['code'])} code cell input(s) visible, e.g. {layout['code'][0]!r}"
        )
    if layout["nbval"]:
        report.problems.append("nbval marker text (NBVAL) visible on the page")


def check_dom(dom: str, report: PageReport, is_notebook: bool) -> None:
    """Checks on the DOM after MathJax ran."""
    soup = BeautifulSoup(dom, "html.parser")
    check_layout(soup, report)
    report.tables = len(soup.find_all("table"))
    maths = soup.select("span.math, div.math")
    report.rendered = sum(1 for m in maths if m.find("mjx-container") is not None)
    if report.rendered < len(maths):
        missing = [
            m.get_text(" ", strip=True)[:60] for m in maths if m.find("mjx-container") is None
        ]
        report.problems.append(
            f"{len(missing)} of {len(maths)} math elements not typeset by MathJax, "
            f"e.g. {missing[0]!r}"
        )
    errors = soup.find_all("mjx-merror") + soup.select("[data-mjx-error]")
    if errors:
        report.problems.append(
            f"{len(errors)} MathJax error(s), e.g. {errors[0].get_text(strip=True)!r}"
        )
    raw = RAW_TEX.search(visible_text(soup))
    if raw:
        report.problems.append(f"raw TeX left in the rendered text near {raw.group(0)!r}")
    if report.page in PAGES_NEEDING_MATH and report.math == 0:
        report.problems.append("page should hold math but has none")
    if is_notebook and report.tables == 0:
        report.problems.append("notebook page shows no <table>")
    if report.page == VERDICTS and report.tables == 0:
        report.problems.append("the Verdicts page should hold a table of claims per chapter")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("html_dir", nargs="?", default="book/_build/html", type=Path)
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--budget-ms", type=int, default=5000, help="--virtual-time-budget")
    parser.add_argument("--timeout-s", type=int, default=60, help="per page, via timeout(1)")
    args = parser.parse_args(argv)

    html_dir: Path = args.html_dir
    if not (html_dir / "intro.html").is_file():
        print(f"check_book: {html_dir}/intro.html not found; build the book first (make book)")
        return 1
    if shutil.which(args.chromium) is None:
        print(f"check_book: {args.chromium} not found; install it (make chromium)")
        return 1

    reports = []
    if not (html_dir / VERDICTS).is_file():
        reports.append(PageReport(VERDICTS, ["page missing (make book writes verdicts.md)"]))
        print(f"check_book: FAIL {VERDICTS}: page missing")
    for path in content_pages(html_dir):
        rel = path.relative_to(html_dir).as_posix()
        report = PageReport(rel)
        t0 = time.perf_counter()
        check_static(path, html_dir, report)
        dom, why = render(path, args.chromium, args.budget_ms, args.timeout_s)
        if dom is None:
            report.problems.append(why)
        else:
            check_dom(dom, report, is_notebook=rel.startswith("notebooks/"))
        report.seconds = time.perf_counter() - t0
        status = "ok  " if not report.problems else "FAIL"
        print(
            f"check_book: {status} {rel:<32} math {report.rendered}/{report.math} typeset, "
            f"{report.tables} table(s), column {report.column_px} px, {report.seconds:.1f} s"
        )
        for problem in report.problems:
            print(f"check_book:      {rel}: {problem}")
        reports.append(report)

    failed = [r for r in reports if r.problems]
    if failed:
        print(f"check_book: {len(failed)} of {len(reports)} page(s) failed the browser check")
        return 1
    print(f"check_book: {len(reports)} page(s) passed the browser check")
    return 0


if __name__ == "__main__":
    sys.exit(main())
