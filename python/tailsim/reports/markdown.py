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
from collections.abc import Iterable

STYLE = (
    "body{font-family:sans-serif;max-width:80em;margin:2em auto}table{border-collapse:collapse}"
    "td,th{border:1px solid #ccc;padding:3px 8px}th{background:#eee}"
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


def markdown_to_html(lines: list[str], base: pathlib.Path, title: str) -> str:
    """The subset of Markdown the reports use (headings, tables, images, bullets,
    paragraphs) as one self-contained HTML page; images are embedded from `base`."""
    body = []
    in_table = False
    for line in lines:
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if set("".join(cells)) <= set("-"):
                continue
            if not in_table:
                body.append("<table>")
                in_table = True
                body.append("<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in cells) + "</tr>")
            else:
                body.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
            continue
        if in_table:
            body.append("</table>")
            in_table = False
        if line.startswith("### "):
            body.append(f"<h3>{html.escape(line[4:])}</h3>")
        elif line.startswith("## "):
            body.append(f"<h2>{html.escape(line[3:])}</h2>")
        elif line.startswith("# "):
            body.append(f"<h1>{html.escape(line[2:])}</h1>")
        elif line.startswith("!["):
            name = line[line.rindex("](") + 2 : -1]
            data = base64.b64encode((base / name).read_bytes()).decode()
            body.append(f'<img alt="{html.escape(name)}" src="data:image/png;base64,{data}" style="max-width:100%">')
        elif line.startswith("- "):
            body.append(f"<p>• {html.escape(line[2:])}</p>")
        elif line:
            body.append(f"<p>{html.escape(line)}</p>")
    if in_table:
        body.append("</table>")
    return (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{STYLE}</style></head><body>{''.join(body)}</body></html>\n"
    )
