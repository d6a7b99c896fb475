"""The one rendering layer of the project's reports: number formats and the
Markdown → self-contained HTML conversion used by the comparison report
(`tailsim.reports.compare`) and the analysis report (`tailsim.reports.analysis`).

Rust writes data (CSV, JSON); everything a reader sees is formatted here.
"""

from __future__ import annotations

import base64
import html
import math
import pathlib
import re
from collections.abc import Iterable

#: The page's style: readable on a phone (390 px) and a desktop; wide tables scroll inside their
#: own box (`.table-wrap`), never the page; long code words break.
STYLE = (
    "body{font-family:system-ui,sans-serif;line-height:1.45;max-width:80em;margin:0 auto;padding:0.5em 1em}"
    "h1{font-size:1.6em;margin:0.4em 0}h2{margin-top:1.6em}"
    ".table-wrap{overflow-x:auto;max-width:100%;margin:0.6em 0}"
    "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;vertical-align:top}th{background:#eee}"
    "img{max-width:100%;height:auto}pre{overflow-x:auto}"
    "p,li,code{overflow-wrap:anywhere}td{overflow-wrap:break-word}"
    ".headerlink{text-decoration:none;color:#bbb;margin-left:0.3em}"
    ".toc ul{margin:0.2em 0}"
)


def fmt(x: float | None, digits: int = 2) -> str:
    """A number for a table: `–` for missing/NaN, `never` for ∞."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if isinstance(x, float) and math.isinf(x):
        return "never"
    return f"{x:.{digits}f}"


def fmt_or_dash(x: float | None, digits: int = 2) -> str:
    """A finite number with `digits` decimals, `—` for missing, NaN or ∞."""
    if x is None or not math.isfinite(x) or x >= 1e300:
        return "—"
    return f"{x:.{digits}f}"


def shortest(x: float) -> str:
    """The shortest decimal that reads back as `x`, integers without a fraction (`2`, `0.05`)."""
    return str(int(x)) if float(x).is_integer() else repr(float(x))


def fmt_pole(re: float, im: float) -> str:
    """`re` for a real pole, `re ± |im|i` for a complex pair (3 decimals)."""
    if abs(im) < 1e-6 * max(math.hypot(re, im), 1e-12) or abs(im) < 1e-9:
        return f"{re:.3f}"
    return f"{re:.3f} ± {abs(im):.3f}i"


def table_head(header: list[str]) -> list[str]:
    """The header and rule lines of a Markdown table."""
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]


def table(header: list[str], rows: Iterable[list[str]]) -> list[str]:
    """A Markdown table."""
    out = table_head(header)
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return out


def slug(heading: str, separator: str = "-") -> str:
    """The anchor of a heading: lower case, letters/digits kept, the rest one `-` (the same in
    the Markdown's table of contents and the HTML's heading ids)."""
    words = re.findall(r"\w+", heading.lower())
    return separator.join(words)


def toc(lines: list[str], level: int = 2) -> list[str]:
    """A linked table of contents (Markdown bullets) of the headings of `level` in `lines`."""
    mark = "#" * level + " "
    return [f"- [{h[len(mark) :]}](#{slug(h[len(mark) :])})" for h in lines if h.startswith(mark)]


def markdown_to_html(lines: list[str], base: pathlib.Path, title: str) -> str:
    """The Markdown `lines` as one self-contained HTML page (Python-Markdown with its tables and
    toc extensions): heading anchors (`slug`), tables wrapped in a scrolling box, a viewport
    for phones, and every image that is a file of `base` embedded as a data URI."""
    import markdown

    body = markdown.markdown(
        "\n".join(lines),
        extensions=["tables", "toc", "sane_lists"],
        extension_configs={"toc": {"slugify": lambda value, separator: slug(value, separator), "permalink": "¶"}},
        output_format="html",
    )
    body = body.replace("<table>", '<div class="table-wrap"><table>').replace("</table>", "</table></div>")

    def embed(m: re.Match) -> str:
        src = html.unescape(m.group(1))
        path = base / src
        if "://" in src or src.startswith("data:") or not path.is_file():
            return m.group(0)
        kind = "svg+xml" if path.suffix == ".svg" else path.suffix.lstrip(".").replace("jpg", "jpeg")
        data = base64.b64encode(path.read_bytes()).decode()
        return f'src="data:image/{kind};base64,{data}"'

    body = re.sub(r'src="([^"]+)"', embed, body)
    return (
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
        "<meta name='viewport' content='width=device-width, initial-scale=1'><link rel='icon' href='data:,'>"
        f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>{body}</body></html>\n"
    )
