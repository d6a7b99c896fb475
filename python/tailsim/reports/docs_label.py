"""Label the hand-typed figures of a document the docs scan reads (`tailsim.reports.docs`):
the tool for switching the scan on for a document (`docs.SCAN_LATER`).

    python -m tailsim.reports.docs_label FILE --left
        the figures the scan refuses, per line;
    python -m tailsim.reports.docs_label FILE --record A-B "how"
        lines A..B (1-based) become a dated history record, `<!-- history: DATE, how -->…
        <!-- /history -->` (DATE: the newest commit of those lines, `git blame`; `--date`
        overrides): marker lines of their own around a paragraph or table, inline markers in a
        list item (so the Markdown stays intact, `test_markers_leave_the_markdown_intact`);
    python -m tailsim.reports.docs_label FILE --text "exact text" "how"
        the same for an exact text (unique in the file), inline;
    python -m tailsim.reports.docs_label FILE --definitions
        every figure still refused goes into `docs/figures_allowed.json` as a definition: only
        after `--left` shows that each is one (a number of the thesis, a parameter, a limit, a
        count, a test bound); a measured figure is generated or recorded instead.

Several `--record` / `--text` options may be given; line numbers are those of the file as it
is before the command.
"""

from __future__ import annotations

import datetime
import json
import pathlib
import re
import subprocess
import sys

from .. import cli
from . import docs

_ITEM = re.compile(r"^(\s*(?:[*-] |\d+\. )(?:\*\*[^*]+\*\*\s*(?:—|:)?\s*)?)")


def blame_date(path: pathlib.Path, first: int, last: int) -> str:
    """The date (UTC, YYYY-MM-DD) of the newest commit among lines `first..last` of `path`
    (uncommitted lines aside; today if none is committed)."""
    out = subprocess.run(
        ["git", "blame", "--line-porcelain", "-L", f"{first},{last}", "--", path.name],
        cwd=path.parent,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    times = [
        int(t) for h, t in re.findall(r"^([0-9a-f]{40}) .*?^author-time (\d+)", out, re.M | re.S) if set(h) != {"0"}
    ]
    when = datetime.datetime.fromtimestamp(max(times), datetime.UTC) if times else datetime.datetime.now(datetime.UTC)
    return when.strftime("%Y-%m-%d")


def opening(date: str, how: str) -> str:
    if "-->" in how or not how.strip():
        raise ValueError(f"how the figures were measured: {how!r} (not empty, no '-->')")
    return f"<!-- history: {date}, {how} -->"


def record_lines(text: str, first: int, last: int, how: str, date: str) -> str:
    """`text` with lines `first..last` (1-based) in a history record."""
    lines = text.split("\n")
    if not 1 <= first <= last <= len(lines):
        raise ValueError(f"lines {first}-{last} outside the file's 1-{len(lines)}")
    begin, end = opening(date, how), "<!-- /history -->"
    line = lines[first - 1]
    if _ITEM.match(line) or line.startswith((" ", "\t")):
        # inline, after the item's first word: a line whose content starts with a comment is an
        # HTML block to CommonMark (the rest of it shown raw)
        start = _ITEM.match(line).end() if _ITEM.match(line) else len(line) - len(line.lstrip())
        word = line.find(" ", start + 1)
        cut = len(line) if word < 0 else word + 1
        lines[first - 1] = line[:cut] + begin + line[cut:]
        lines[last - 1] += end
    else:
        lines[first - 1 : last] = [begin, *lines[first - 1 : last], end]
    return "\n".join(lines)


def record_text(text: str, exact: str, how: str, date: str) -> str:
    """`text` with the (unique) `exact` text in an inline history record."""
    if text.count(exact) != 1:
        raise ValueError(f"{exact[:60]!r} occurs {text.count(exact)} times (must be once)")
    i = j = text.index(exact)
    line_start = text.rfind("\n", 0, i) + 1
    if not text[line_start:i].strip():  # at a line's start: the opening ends the line before
        j = line_start - 1
        if j < 0 or text[text.rfind("\n", 0, j) + 1 : j].strip() == "":
            raise ValueError(f"{exact[:60]!r} starts a paragraph: record its lines (--record) instead")
    elif re.fullmatch(r"\s*(?:[*-] |\d+\. )", text[line_start:i]):
        raise ValueError(f"{exact[:60]!r} starts a list item: record its lines (--record) instead")
    return text[:j] + opening(date, how) + text[j:i] + exact + "<!-- /history -->" + text[i + len(exact) :]


def refused(root: pathlib.Path, rel: str) -> list[tuple[int, str]]:
    """(line, figure) of every figure of `rel` the scan refuses."""
    allowed = docs.load_allowed(root).get(rel, {})
    text = (root / rel).read_text()
    bad = docs.untagged_in(rel, docs.figures(text), allowed)
    return [(int(b.split(":")[1]), b.split(": ", 1)[1]) for b in bad]


def add_definitions(root: pathlib.Path, rel: str) -> list[str]:
    """Allow-list every refused figure of `rel` as a definition; the figures added."""
    toks = [tok for _, tok in refused(root, rel)]
    path = root / docs.DOCS_DIR / "figures_allowed.json"
    allowed = json.loads(path.read_text())
    allowed["files"].setdefault(rel, {}).setdefault("definitions", []).extend(toks)
    path.write_text(json.dumps(allowed, indent=1, ensure_ascii=False) + "\n")
    return toks


def main(argv: list[str] | None = None) -> int:
    ap = cli.Parser(prog="python -m tailsim.reports.docs_label", description=__doc__.split("\n\n")[0])
    ap.add_argument("file", help="the document, relative to the checkout (e.g. crates/lqr-control/README.md)")
    ap.add_argument("--left", action="store_true", help="list the figures the scan refuses")
    ap.add_argument("--record", nargs=2, action="append", default=[], metavar=("A-B", "HOW"))
    ap.add_argument("--text", nargs=2, action="append", default=[], metavar=("TEXT", "HOW"))
    ap.add_argument("--definitions", action="store_true", help="allow-list every refused figure as a definition")
    ap.add_argument("--date", help="the records' date (default: the newest commit of their lines)")
    a = ap.parse_args(argv)
    root = docs.ROOT
    path = root / a.file

    def run() -> int:
        if not path.is_file():
            ap.error(f"argument file: {a.file} is not a file under {root}")
        text = path.read_text()
        spans = []
        for rng, how in a.record:
            m = re.fullmatch(r"(\d+)(?:-(\d+))?", rng)
            if not m:
                ap.error(f"argument --record: {rng!r} is not A-B")
            spans.append((int(m[1]), int(m[2] or m[1]), how))
        for first, last, how in sorted(spans, reverse=True):  # bottom up: the numbers stay valid
            text = record_lines(text, first, last, how, a.date or blame_date(path, first, last))
        for exact, how in a.text:
            line = text[: text.index(exact)].count("\n") + 1 if exact in text else 1
            text = record_text(text, exact, how, a.date or blame_date(path, line, line + exact.count("\n")))
        if spans or a.text:
            path.write_text(text)
        if a.definitions:
            print(f"{a.file}: {len(add_definitions(root, a.file))} figures allow-listed as definitions")
        if a.left or not (spans or a.text or a.definitions):
            lines = path.read_text().split("\n")
            for n, tok in refused(root, a.file):
                print(f"{n}: {tok} | {lines[n - 1].strip()[:110]}")
        return 0

    return cli.guard(ap.prog, a.debug, run)


if __name__ == "__main__":
    sys.exit(main())
