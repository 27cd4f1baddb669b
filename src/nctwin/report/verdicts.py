"""The Verdicts page: a status per chapter, then every claim of every chapter in one table,
from ``results/*/claims.json``.

``make book`` runs ``python -m nctwin.report.verdicts book/verdicts.md`` before Jupyter Book, so
the page always shows the claims the committed (or just re-executed) notebooks wrote. It is a
Markdown page, not a notebook: it computes nothing, only reads the JSON files, and its links to
the chapters are MyST links that Sphinx checks (a missing section fails ``make book``).

The page opens with one status per chapter (:func:`chapter_status`): reproduced, partly
reproduced, not reproduced, or not tested under the paper's conditions, with one sentence of
why. Then one row per claim: the chapter, the claim's text and id, whose it is (the paper's or
ours), the paper's value, ours, the bar it is judged against, the verdict (holds, fails, or not
tested, with the unmet conditions), and a link to the section that explains it. The paper's value is
the record's ``paper`` field where a chapter gives one, else what the claim's text quotes after
"paper" (``"(paper 0.8-2.2 %)"`` gives ``0.8-2.2 %``), else empty. The section is the one whose
prose names the claim's id (in backticks or not); if none does, the section holding the
notebook's ``report_claims`` cell.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from .. import paths
from .html import format_value

__all__ = [
    "INTRO_MARKERS",
    "STATUSES",
    "ChapterClaims",
    "chapter_claims",
    "chapter_status",
    "paper_value",
    "render",
    "section_of",
    "slugify",
    "status_lines",
    "status_of",
    "update_intro",
]

#: The text a claim quotes as the paper's value: "(paper 3-6 %)", "(..; paper: 20.8 %, Sec. 3.2)".
_PAPER_IN_TEXT = re.compile(r"\bpaper:? ([^;)]+)")
#: Deepest heading level that gets an anchor (``myst_heading_anchors`` in book/_config.yml).
HEADING_ANCHORS = 4


def slugify(title: str) -> str:
    """The anchor MyST gives a heading (GitHub style, as ``mdit_py_plugins.anchors``).

    Examples
    --------
    >>> slugify('Table 3 analogue: "machine B"')
    'table-3-analogue-machine-b'
    """
    return re.sub(r"[^\w\u4e00-\u9fff\- ]", "", title.lower().replace(" ", "-"))


def paper_value(record: dict) -> str:
    """The paper's value of a claim record: its ``paper`` field, else quoted in its text."""
    if record.get("paper"):
        return str(record["paper"])
    match = _PAPER_IN_TEXT.search(record.get("text", ""))
    return match.group(1).strip() if match else ""


@dataclass(frozen=True)
class ChapterClaims:
    """One chapter's claims and where its notebook explains them.

    Attributes
    ----------
    stem
        Notebook stem, e.g. ``"chien2023_bilstm"``.
    title
        The notebook's first heading.
    claims
        The records of ``results/<stem>/claims.json``.
    headings
        ``(cell index, level, text, slug)`` of every heading of the notebook's Markdown cells.
    sources
        Source of every cell, by index.
    """

    stem: str
    title: str
    claims: list[dict]
    headings: list[tuple[int, int, str, str]]
    sources: list[tuple[str, str]]


def _headings(cells: list[dict]) -> list[tuple[int, int, str, str]]:
    out, seen = [], set()
    for i, cell in enumerate(cells):
        if cell["cell_type"] != "markdown":
            continue
        fence = False
        for line in "".join(cell["source"]).splitlines():
            if line.lstrip().startswith(("```", "~~~")):
                fence = not fence
            match = None if fence else re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if match:
                text = re.sub(r"[`*]", "", match.group(2))
                slug = base = slugify(text)
                k = 0
                while slug in seen:
                    k += 1
                    slug = f"{base}-{k}"
                seen.add(slug)
                out.append((i, len(match.group(1)), text, slug))
    return out


def chapter_claims(stem: str, results_dir: Path, notebooks_dir: Path) -> ChapterClaims:
    """Read one chapter's claims and its notebook's headings."""
    claims = json.loads((results_dir / stem / "claims.json").read_text(encoding="utf-8"))
    cells = json.loads((notebooks_dir / f"{stem}.ipynb").read_text(encoding="utf-8"))["cells"]
    headings = _headings(cells)
    title = next((t for _, level, t, _ in headings if level == 1), stem)
    sources = [(c["cell_type"], "".join(c["source"])) for c in cells]
    return ChapterClaims(stem, title, claims, headings, sources)


def section_of(chapter: ChapterClaims, claim_id: str) -> tuple[str, str]:
    """``(heading text, slug)`` of the section that explains a claim ("" slug: the chapter).

    The first Markdown cell naming ``claim_id`` as a word decides; if none does, the cell that
    calls ``report_claims``. The section is the last heading (level 2 to
    :data:`HEADING_ANCHORS`) at or before that cell.
    """
    word = re.compile(rf"(?<![\w-]){re.escape(claim_id)}(?![\w-])")
    cell = next(
        (
            i
            for i, (kind, src) in enumerate(chapter.sources)
            if kind == "markdown" and word.search(src)
        ),
        None,
    )
    if cell is None:
        cell = next(
            (i for i, (kind, src) in enumerate(chapter.sources)
             if kind == "code" and "report_claims(" in src),
            len(chapter.sources),
        )  # fmt: skip
    before = [h for h in chapter.headings if h[0] <= cell and 2 <= h[1] <= HEADING_ANCHORS]
    return (before[-1][2], before[-1][3]) if before else (chapter.title, "")


def _cell(text: str) -> str:
    """Text safe in a Markdown table cell."""
    return text.replace("|", "\\|").replace("\n", " ")


def _number(value: float | None) -> str:
    return (
        "-"
        if value is None or (isinstance(value, float) and math.isnan(value))
        else (format_value(float(value), 4))
    )


#: A chapter's status, from its paper's claims (:func:`chapter_status`).
STATUSES = (
    "reproduced",
    "partly reproduced",
    "not reproduced",
    "not tested under the paper's conditions",
    "checks of our own only",
)


def _ours(record: dict) -> str:
    """The value, and for a learned claim the interval and how many single networks pass, each
    on a line of its own (the column does not wrap)."""
    text = _number(record["value"])
    if "interval" in record:
        low, high = record["interval"]
        text += f"<br>({_number(low)} to {_number(high)})"
    if "seeds" in record:
        text += f"<br>{record['seeds_passing']} of {record['seeds']} nets"
    return text


def _status(record: dict) -> str:
    """A record's status; records written before claims had one give holds or fails."""
    return record.get("status") or ("holds" if record["holds"] else "fails")


def grouped(ids: list[str]) -> str:
    """Condition ids for a sentence: ids that differ only in their numbers are one entry, the
    numbers as ``*`` and the count after it (``pocket*_cam_err (8)``); the rest as they are.

    >>> grouped(["pocket2_cam_err", "logger_rate", "pocket1_cam_err", "pocket1_cls"])
    'logger_rate, pocket*_cam_err (2), pocket1_cls'
    """
    families: dict[str, list[str]] = {}
    for i in sorted(set(ids)):
        families.setdefault(re.sub(r"\d+(?:\.\d+)?", "*", i), []).append(i)
    entries = [m[0] if len(m) == 1 else f"{key} ({len(m)})" for key, m in families.items()]
    return ", ".join(sorted(entries))


def status_of(records: list[dict]) -> tuple[str, str]:
    """A chapter's status (one of :data:`STATUSES`) and one sentence of why, from its claims'
    records (:meth:`~nctwin.report.claims.Claim.to_dict`).

    Of the paper's claims (``whose`` ``"paper"``): *reproduced* where every one is tested and
    holds; *not tested under the paper's conditions* where none is tested (their conditions
    are unmet, and named); *not reproduced* where none of those tested holds; else *partly
    reproduced*.
    """
    paper = [r for r in records if r.get("whose", "paper") == "paper"]
    if not paper:
        return STATUSES[4], f"The chapter's {len(records)} claims are checks of our own."
    count = {k: sum(_status(r) == k for r in paper) for k in ("holds", "fails", "not tested")}
    unmet = [u for r in paper for u in r.get("unmet", [])]
    why = (f"{count['holds']} of the paper's {len(paper)} claims hold, {count['fails']} fail"
           + (f", {count['not tested']} not tested (unmet: {grouped(unmet)})"
              if count["not tested"] else "") + ".")  # fmt: skip
    if count["not tested"] == len(paper):
        status = STATUSES[3]
    elif count["holds"] == len(paper):
        status = STATUSES[0]
    elif count["holds"] == 0:
        status = STATUSES[2]
    else:
        status = STATUSES[1]
    return status, why


def chapter_status(chapter: ChapterClaims) -> tuple[str, str]:
    """:func:`status_of` the chapter's claims."""
    return status_of(chapter.claims)


def status_lines(chapters: list[ChapterClaims], prefix: str = "") -> list[str]:
    """One Markdown list item per chapter: its title, linked (``prefix`` before
    ``notebooks/``), its status and why."""
    lines = []
    for c in chapters:
        status, why = chapter_status(c)
        lines.append(f"- **[{_cell(c.title)}]({prefix}notebooks/{c.stem}.ipynb)**: "
                     f"{status}. {why}")  # fmt: skip
    return lines


#: The lines of ``book/intro.md`` between these two that :func:`main` rewrites with
#: :func:`status_lines`.
INTRO_MARKERS = ("<!-- verdicts:status (generated by make book; do not edit) -->",
                 "<!-- /verdicts:status -->")  # fmt: skip


def update_intro(text: str, lines: list[str]) -> str:
    """``text`` with the lines between :data:`INTRO_MARKERS` replaced by ``lines``.

    Raises
    ------
    ValueError
        If ``text`` lacks either marker, or holds them in the wrong order.
    """
    begin, end = (text.find(m) for m in INTRO_MARKERS)
    if begin < 0 or end < begin:
        raise ValueError(f"intro: the markers {INTRO_MARKERS} are missing or out of order")
    head = text[: begin + len(INTRO_MARKERS[0])]
    return head + "\n" + "".join(f"{ln}\n" for ln in lines) + text[end:]


#: How a claim's status reads in the table.
_VERDICT_HTML = {
    "holds": '<span class="nctwin-holds">holds</span>',
    "fails": '<span class="nctwin-fails">fails</span>',
    "not tested": '<span class="nctwin-untested">not tested</span>',
}


def render(chapters: list[ChapterClaims]) -> str:
    """The Verdicts page as MyST Markdown: a status line per chapter, then every claim."""
    n = sum(len(c.claims) for c in chapters)
    counts = {k: sum(_status(r) == k for c in chapters for r in c.claims) for k in _VERDICT_HTML}
    lines = [
        "# Verdicts",
        "",
        "<!-- Generated by `python -m nctwin.report.verdicts` from results/*/claims.json "
        "(make book); do not edit. -->",
        "",
        f"Every claim the chapters check, {n} in all: {counts['holds']} hold, "
        f"{counts['fails']} fail and {counts['not tested']} are not tested, because a condition "
        "of the paper's experiment they depend on is not met here (a claim that is not tested "
        "neither holds nor fails). A paper's claim is checked at the paper's own level, ours "
        "(*whose*: ours) are checks of the project's own beyond the paper.",
        "",
        "## By chapter",
        "",
    ]
    lines += status_lines(chapters)
    lines += [
        "",
        "## Every claim",
        "",
        "Each row: the claim, whose it is, the value the paper reports where the claim quotes "
        "one, ours, the bar (our value against the threshold), the verdict and the section of "
        "the chapter that explains it. A claim that fails is kept and explained there. A "
        "learned claim is judged on the ensemble of its seeds' networks; beside its value, a "
        "bootstrap interval over the seeds and how many single networks pass on their own.",
    ]
    for chapter in chapters:
        lines += [
            "",
            f"### {chapter.title.split(':')[0]}",
            "",
            ":::{container} nctwin-verdicts",
            "| claim | whose | paper | ours | bar | verdict | explained in |",
            "| --- | --- | --- | --- | --- | --- | --- |",
        ]
        for r in chapter.claims:
            heading, slug = section_of(chapter, r["id"])
            target = f"notebooks/{chapter.stem}.ipynb" + (f"#{slug}" if slug else "")
            status = _status(r)
            verdict = _VERDICT_HTML[status] + (
                f" (unmet: {grouped(r['unmet'])})" if status == "not tested" else ""
            )
            lines.append(
                f"| {_cell(r['text'])} (`{_cell(r['id'])}`) | {r.get('whose', 'paper')} "
                f"| {_cell(paper_value(r))} | {_ours(r)} "
                f"| {r['op']}&nbsp;{_number(r['threshold'])} | {verdict} "
                f"| [{_cell(heading)}]({target}) |"
            )
        lines.append(":::")
    return "\n".join(lines) + "\n"


def chapters_in_order(toc: Path, results_dir: Path, notebooks_dir: Path) -> list[ChapterClaims]:
    """Every chapter with a ``claims.json``, in the order of the book's table of contents."""
    stems = sorted(p.parent.name for p in results_dir.glob("*/claims.json"))
    order = re.findall(r"file:\s*notebooks/([\w.-]+)", toc.read_text(encoding="utf-8"))
    stems.sort(key=lambda s: (order.index(s) if s in order else len(order), s))
    return [chapter_claims(s, results_dir, notebooks_dir) for s in stems]


def main(argv: list[str] | None = None) -> int:
    """``python -m nctwin.report.verdicts OUT.md``: write the page (default book/verdicts.md)
    and the chapters' statuses in the book's intro (``intro.md`` beside the page, where it
    holds :data:`INTRO_MARKERS`)."""
    parser = argparse.ArgumentParser(
        prog="python -m nctwin.report.verdicts",
        description="Write the book's Verdicts page from results/*/claims.json.",
    )
    parser.add_argument("out", nargs="?", type=Path, help="the page (default book/verdicts.md)")
    args = parser.parse_args(argv)
    root = paths.repo_root()
    out = args.out or root / "book" / "verdicts.md"
    chapters = chapters_in_order(
        root / "book" / "_toc.yml", paths.results_dir(), root / "notebooks"
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(render(chapters), encoding="utf-8")
    intro = out.parent / "intro.md"
    if intro.is_file() and INTRO_MARKERS[0] in (text := intro.read_text(encoding="utf-8")):
        updated = update_intro(text, status_lines(chapters))
        if updated != text:
            intro.write_text(updated, encoding="utf-8")
    n = sum(len(c.claims) for c in chapters)
    print(f"verdicts: {n} claims of {len(chapters)} chapters -> {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
