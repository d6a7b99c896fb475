"""The verdict: which controller is better, by how much and under which conditions, read
from one run's result files (nothing typed in by hand, no controller named in the code:
the controllers are the ones the files hold).

Sources, each optional (a condition whose file is missing is reported as not measured):

* `<out>/campaign/results.parquet` — the paired Monte-Carlo campaign (`tailsim.campaign`):
  uncertain plants (Table 5.1 factors) in steady wind and a 1 − cos gust, one condition per
  configuration (thesis / tuned) × state source (perfect / avionics). Completion with its
  95 % Wilson interval per controller; the paired differences (best − each other, same
  samples) with 95 % percentile-bootstrap intervals.
* `<out>/metrics.json` — the nominal missions of `tailsim.reports.compare`: one run per
  controller and mission (no interval), with the transitions as flown.
* `<out>/analysis/wind_envelope.json` — whole missions of the nominal plant in a steady wind
  of every speed and bearing (`cargo run -p analysis -- wind-envelope`): cells held.

`python -m tailsim.reports.verdict OUT` prints it (the end of `scripts/main.sh`);
`python -m tailsim.reports.verdict --docs` rewrites the generated tables of the README and
docs/CAMPAIGN.md from the committed full-run summary `docs/campaign_full_run.json`
(`--check`: only compare; tests/test_readme.py runs it).
"""

from __future__ import annotations

import json
import math
import pathlib
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import cli

ROOT = pathlib.Path(__file__).resolve().parents[3]
FULL_RUN = ROOT / "docs" / "campaign_full_run.json"


@dataclass
class Finding:
    """One condition's answer."""

    condition: str
    """What was flown (Markdown)."""
    better: str | None
    """The controller that is better under it (its key), None where the data do not separate them."""
    by: str
    """By how much, with the intervals (Markdown)."""
    source: str
    """The result file it is read from."""
    short: str = ""
    """The condition in a few words, for the one-sentence summary."""
    detail: list[str] = field(default_factory=list)
    cells: dict[str, str] = field(default_factory=dict)
    """Each controller's figure under the condition (its key → Markdown), for the side-by-side table."""


def label(key: str) -> str:
    """How a controller key (`lqr`, …) is written in the reports."""
    return str(key).upper()


def _f(x: float, nd: int = 2) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{x:.{nd}f}"


def _signed(x: float, nd: int = 2) -> str:
    return "–" if not math.isfinite(x) else f"{x:+.{nd}f}".replace("-", "−")


def _interval(ci, nd: int = 2, signed: bool = False) -> str:
    f = _signed if signed else _f
    return f"[{f(ci[0], nd)}, {f(ci[1], nd)}]"


# --- the paired Monte-Carlo campaign --------------------------------------------------------------------------


def _campaign_columns(folder: pathlib.Path) -> dict[str, np.ndarray] | None:
    path = folder / "results.parquet"
    if not path.exists():
        return None
    import pyarrow.parquet as pq

    return {k: np.asarray(v) for k, v in pq.read_table(path).to_pydict().items()}


def _conditions_text(spec: Mapping[str, Any]) -> str:
    aero = "global (post-stall)" if spec.get("aero_model", 1) == 1 else "thesis (linear)"
    return (
        f"Table 5.1 factors within τ = {spec['tau_aero']:g} (aero) / {spec['tau_mass']:g} (mass, inertia), "
        f"steady wind ≤ {spec['wind_max']:g} m/s and a 1 − cos gust ≤ {spec['gust_max']:g} m/s, "
        f"{aero} aerodynamics{_turbulence_and_criterion(spec)}"
    )


#: Dryden turbulence intensities of the campaign's `--turbulence-max` (0 none … 3 severe).
TURBULENCE = ("none", "light", "moderate", "severe")


def _turbulence_and_criterion(spec: Mapping[str, Any]) -> str:
    """', Dryden turbulence up to …; completed = flown to the end within … m' where recorded."""
    text = ""
    t = spec.get("turbulence_max")
    if t:
        text += f", Dryden turbulence up to {TURBULENCE[int(t)]} (perfect-state runs)"
    e = spec.get("error_limit_m")
    if e is not None and math.isfinite(e) and e < 1e6:
        text += f"; completed = flown to the end within {e:g} m of the controller's reference"
    return text


def campaign_findings(folder: str | pathlib.Path) -> list[Finding]:
    """One finding per configuration × state source of the campaign in `folder` that flew
    at least two controllers."""
    from ..campaign.report import _arm_mask, arms, bootstrap_mean_ci, paired, wilson_interval

    folder = pathlib.Path(folder)
    cols = _campaign_columns(folder)
    if cols is None:
        return []
    spec = json.loads((folder / "campaign.json").read_text())["spec"]
    source = str(folder / "results.parquet")
    found = []
    groups = sorted({(a[1], a[2]) for a in arms(cols)}, key=lambda g: (g[1] != "perfect", g[0] != "tuned", g))
    for config, state in groups:
        members = [a for a in arms(cols) if (a[1], a[2]) == (config, state)]
        if len(members) < 2:
            continue
        stats = {}
        for a in members:
            m = _arm_mask(cols, a)
            n, k = int(m.sum()), int(cols["completed"][m].sum())
            ok = m & cols["completed"].astype(bool)
            rms = float(np.median(cols["rms_err"][ok].astype(float))) if ok.any() else math.nan
            stats[a] = (n, k, wilson_interval(k, n), rms)
        ranked = sorted(members, key=lambda a: (-stats[a][1] / max(stats[a][0], 1), _nan_last(stats[a][3])))
        best = ranked[0]
        per = "; ".join(
            f"{label(a[0])} {stats[a][1]}/{stats[a][0]} (P = {_f(stats[a][1] / max(stats[a][0], 1))} "
            f"{_interval(stats[a][2])}" + (f", median RMS error {_f(stats[a][3])} m)" if stats[a][1] else ")")
            for a in ranked
        )
        separated, diffs = True, []
        better = best[0]
        for other in ranked[1:]:
            _, cb, co = paired(cols, best, other, "completed")
            d = cb.astype(float) - co.astype(float)
            dc = (float(d.mean()) if d.size else math.nan, bootstrap_mean_ci(d))
            _, eb, eo = paired(cols, best, other, "rms_err")
            both = (cb > 0) & (co > 0)
            de = (eb - eo)[both]
            de = de[np.isfinite(de)]
            er = (float(de.mean()) if de.size else math.nan, bootstrap_mean_ci(de), int(de.size))
            error = (
                f"RMS position error {_signed(er[0])} m {_interval(er[1], signed=True)} ({er[2]} samples both "
                "completed)"
                if er[2]
                else "no sample completed by both"
            )
            diffs.append(
                f"{label(best[0])} − {label(other[0])} on the same {d.size} samples: completion "
                f"{_signed(dc[0])} {_interval(dc[1], signed=True)}, {error}"
            )
            if dc[1][0] > 0:
                continue  # completes more often, the interval excludes 0
            if er[2] and er[1][1] < 0:
                continue  # as often within the interval, but a smaller error, the interval excludes 0
            if er[2] and er[1][0] > 0 and len(ranked) == 2:
                better = other[0]  # completion not separated, the other has the smaller error
                continue
            separated = False
        n = len(set(cols["sample_id"][_arm_mask(cols, best)].tolist()))
        found.append(
            Finding(
                condition=f"uncertain plants in wind and gusts ({n} samples), {config} configuration, {state} state",
                better=better if separated else None,
                by=f"completed: {per}; paired: " + "; ".join(diffs),
                source=source,
                short=f"{config} configuration, uncertain plants, {state} state",
                cells={
                    a[0]: f"P(complete) {_f(stats[a][1] / max(stats[a][0], 1), 3)} {_interval(stats[a][2], 3)}"
                    for a in members
                },
            )
        )
    if found:
        found[-1].detail.append("Uncertain plants: " + _conditions_text(spec) + ".")
    return found


def _nan_last(x: float) -> float:
    return x if math.isfinite(x) else math.inf


# --- the nominal missions -------------------------------------------------------------------------------------


def nominal_findings(path: str | pathlib.Path) -> list[Finding]:
    """One finding per nominal mission of `metrics.json` (`tailsim.reports.compare`)."""
    path = pathlib.Path(path)
    if not path.exists():
        return []
    data = json.loads(path.read_text())
    missions: dict[str, dict[str, dict]] = {}
    for m in data.values():
        if "mission" in m and "controller" in m:
            missions.setdefault(m["mission"], {})[m["controller"]] = m
    found = []
    for mission, runs in missions.items():
        if len(runs) < 2:
            continue

        def worst(m: dict) -> float:
            return max((e for e in m["max_error"] if e is not None and math.isfinite(e)), default=math.inf)

        ranked = sorted(runs, key=lambda k: (not runs[k]["completed"], worst(runs[k])))
        best, rest = ranked[0], ranked[1:]
        req = runs[best].get("requested", [math.nan, math.nan])
        cells = []
        for k in ranked:
            m = runs[k]
            fl = m.get("flown_transition", [math.nan, math.nan])
            state = "completed" if m["completed"] else f"not completed ({m['reason']})"
            cells.append(
                f"{label(k)} {state}, largest position error {_f(worst(m))} m, transitions flown in "
                f"{_f(fl[0], 1)} / {_f(fl[1], 1)} s"
            )
        ok = runs[best]["completed"] and all(
            not runs[k]["completed"] or worst(runs[k]) > worst(runs[best]) + 1e-9 for k in rest
        )
        found.append(
            Finding(
                condition=f"nominal plant, no wind, {mission} mission (T1 / T2 requested {_f(req[0], 1)} / "
                f"{_f(req[1], 1)} s)",
                better=best if ok else None,
                by="; ".join(cells) + " (one run each, no interval)",
                source=str(path),
                short=f"nominal {mission} mission",
                cells={
                    k: (f"completed, largest error {_f(worst(runs[k]))} m" if runs[k]["completed"] else "not completed")
                    for k in ranked
                },
            )
        )
    return found


# --- the wind envelope ----------------------------------------------------------------------------------------


def wind_findings(path: str | pathlib.Path) -> list[Finding]:
    """One finding per mission × wind form of the wind envelope (`wind_envelope.json`)."""
    path = pathlib.Path(path)
    if not path.exists():
        return []
    w = json.loads(path.read_text())
    cells = w.get("cells", [])
    found = []
    for mission, wind in dict.fromkeys((c["mission"], c["wind"]) for c in cells):
        mine = [c for c in cells if (c["mission"], c["wind"]) == (mission, wind)]
        ctrls = list(dict.fromkeys(c["controller"] for c in mine))
        if len(ctrls) < 2:
            continue
        held = {k: [c for c in mine if c["controller"] == k] for k in ctrls}
        count = {k: sum(bool(c["held"]) for c in held[k]) for k in ctrls}

        ranked = sorted(ctrls, key=lambda k: -count[k])
        best = ranked[0]
        found.append(
            Finding(
                condition=f"nominal plant in steady wind of every speed and bearing, {mission} mission, {wind} wind",
                better=best if all(count[best] > count[k] for k in ranked[1:]) else None,
                by="; ".join(f"{label(k)} holds {count[k]}/{len(held[k])} cells, {_reach(held[k])}" for k in ranked)
                + " (a grid, no interval)",
                source=str(path),
                short=f"wind envelope, {mission} mission, {wind} wind",
                cells={k: f"{count[k]}/{len(held[k])} cells held, {_reach(held[k])}" for k in ranked},
            )
        )
    return found


def _reach(cells: list[dict]) -> str:
    """Up to which wind speed every cell (every bearing, every lower speed) is held."""
    ok = [s for s in sorted({c["speed"] for c in cells}) if all(c["held"] for c in cells if c["speed"] <= s)]
    if not ok:
        return "not held at every bearing at any speed"
    return "held at every bearing only without wind" if max(ok) == 0 else f"held at every bearing up to {max(ok):g} m/s"


def collect(out: str | pathlib.Path) -> list[Finding]:
    """Every finding of the run in `out`: the campaign, the wind envelope, the nominal missions."""
    out = pathlib.Path(out)
    found = (
        campaign_findings(out / "campaign")
        + wind_findings(out / "analysis" / "wind_envelope.json")
        + nominal_findings(out / "metrics.json")
    )
    for f in found:
        f.source = str(pathlib.Path(f.source).relative_to(out))
    return found


def overall(findings: list[Finding]) -> str:
    """One sentence: which controller is better under which of the measured conditions."""
    if not findings:
        return "No result files: nothing was measured in this run."
    wins: dict[str, list[str]] = {}
    for f in findings:
        if f.better:
            wins.setdefault(label(f.better), []).append(f.short or f.condition)
    open_ = [f.short or f.condition for f in findings if f.better is None]
    if not wins:
        return f"No controller is separated from the others in any of the {len(findings)} conditions measured."
    ranked = sorted(wins, key=lambda k: -len(wins[k]))
    parts = [
        f"{k} is better in {len(wins[k])} of the {len(findings)} conditions ({'; '.join(wins[k])})" for k in ranked
    ]
    if open_:
        parts.append(f"not separated in {len(open_)} ({'; '.join(open_)})")
    return ", ".join(parts) + "."


def markdown(findings: list[Finding], heading: str = "## Verdict") -> list[str]:
    """The verdict as Markdown: one sentence, then one row per condition."""
    md = [heading, "", f"**{overall(findings)}**", ""]
    if not findings:
        return md
    md += [
        "| condition | better | by how much (95 % intervals) |",
        "|---|---|---|",
    ]
    for f in findings:
        md.append(f"| {f.condition} | {label(f.better) if f.better else 'not separated'} | {f.by} |")
    md += side_by_side(findings)
    for f in findings:
        for d in f.detail:
            md += ["", d]
    sources = sorted({f.source for f in findings})
    md += ["", "Read from this run's " + ", ".join(f"`{s}`" for s in sources) + "."]
    return md


def _ordered(keys) -> list[str]:
    """Distinct controller keys in the reports' order (`tailsim.campaign.sampling.ORDER`: the
    thesis's controllers first), unknown keys after them as they come."""
    from ..campaign.sampling import ORDER

    order = {k: i for i, k in enumerate(ORDER)}
    seen = list(dict.fromkeys(keys))
    return sorted(seen, key=lambda k: (order.get(k, len(order)), seen.index(k)))


def side_by_side(findings: list[Finding]) -> list[str]:
    """The controllers side by side: one column per controller, one row per condition (the
    campaign's completion with its 95 % Wilson interval, the wind envelope's cells held, the
    nominal missions' largest error); – where a controller was not flown under it."""
    ctrls = _ordered(k for f in findings for k in f.cells)
    if len(ctrls) < 2:
        return []
    md = [
        "",
        "Side by side:",
        "",
        "| condition | " + " | ".join(label(k) for k in ctrls) + " | better |",
        "|---|" + "---|" * (len(ctrls) + 1),
    ]
    for f in findings:
        cells = " | ".join(f.cells.get(k, "–") for k in ctrls)
        md.append(f"| {f.short or f.condition} | {cells} | {label(f.better) if f.better else 'not separated'} |")
    return md


def text(findings: list[Finding]) -> str:
    """The verdict as plain text for a terminal."""
    lines = ["Verdict: " + overall(findings)]
    for f in findings:
        who = label(f.better) if f.better else "not separated"
        lines.append(f"- {_plain(f.condition)}: {who}. {_plain(f.by)}")
    return "\n".join(lines)


def _plain(s: str) -> str:
    return re.sub(r"[*`]", "", s)


# --- the README's headline table -------------------------------------------------------------------------------


def headline_table(summary: Mapping[str, Any]) -> list[str]:
    """The README's headline: completion per controller (95 % Wilson interval) and the median
    RMS position error of the completed runs, per configuration × state source of a campaign
    summary (`tailsim.campaign.section.summarize`, e.g. `docs/campaign_full_run.json`).
    Better: the controller whose completion interval lies above every other's."""
    arms_ = {tuple(k.split("/")): v for k, v in summary["arms"].items()}
    ctrls = _ordered(a[0] for a in arms_)
    groups = sorted({a[1:] for a in arms_}, key=lambda g: (g[1] != "perfect", g[0] != "tuned", g))
    header = [
        "configuration, state",
        "samples",
        *(f"{label(k)}: P(complete) [95 %], median RMS error" for k in ctrls),
    ]
    header.append("better")
    md = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for g in groups:
        cells, present = [], [k for k in ctrls if (k, *g) in arms_]
        n = max(arms_[(k, *g)]["runs"] for k in present)
        for k in ctrls:
            r = arms_.get((k, *g))
            if r is None:
                cells.append("–")
                continue
            err = f"{_f(r['median_completed']['rms_err'])} m" if r["completed"] else "no run completed"
            fewer = f" ({r['runs']} samples)" if r["runs"] != n else ""
            cells.append(f"{_f(r['p'], 3)} {_interval(r['wilson95'], 3)}, {err}{fewer}")
        top = max(present, key=lambda k: arms_[(k, *g)]["p"])
        sep = all(arms_[(top, *g)]["wilson95"][0] > arms_[(k, *g)]["wilson95"][1] for k in present if k != top)
        md.append(f"| {g[0]}, {g[1]} | {n} | " + " | ".join(cells) + f" | {label(top) if sep else 'not separated'} |")
    s = summary["spec"]
    md += [
        "",
        f"Paired Monte-Carlo, seed {s['seed']}: {_conditions_text(s)}; the default mission "
        f"({sum(s['mission'].values()):g} s). Generated from `docs/campaign_full_run.json`.",
    ]
    return md


def full_run_tables(summary: Mapping[str, Any]) -> list[str]:
    """The full run's tables for `docs/CAMPAIGN.md`: completion per arm, the paired differences, runtime."""
    from ..campaign import section

    return section.markdown(summary, "")[2:]


#: The generated blocks of the documentation: file (from the checkout) → (block name, lines of a summary).
DOCS = {
    "README.md": ("headline table", headline_table),
    "docs/CAMPAIGN.md": ("full-run tables", full_run_tables),
}


def markers(name: str) -> tuple[str, str]:
    """The comment lines that enclose a generated block."""
    return (
        f"<!-- {name}: generated by `python -m tailsim.reports.verdict --docs` from docs/campaign_full_run.json -->",
        f"<!-- end of the generated {name} -->",
    )


def with_generated(text: str, name: str, lines: list[str]) -> str:
    """`text` with the block `name` (between its `markers`) replaced by `lines`."""
    begin, end = markers(name)
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        raise ValueError(f"no generated block {name!r} (markers {begin!r} … {end!r})")
    return text[: i + len(begin)] + "\n" + "\n".join(lines) + "\n" + text[j:]


def regenerate(root: pathlib.Path = ROOT, summary: Mapping[str, Any] | None = None, write: bool = True) -> list[str]:
    """Rewrite every generated block of `DOCS` under `root` from the full-run summary
    (default: `docs/campaign_full_run.json`); the files whose blocks were stale."""
    summary = json.loads((root / "docs" / "campaign_full_run.json").read_text()) if summary is None else summary
    stale = []
    for file, (name, make) in DOCS.items():
        path = root / file
        old = path.read_text()
        new = with_generated(old, name, make(summary))
        if new != old:
            stale.append(file)
            if write:
                path.write_text(new)
    return stale


def main(argv: list[str] | None = None) -> int:
    ap = cli.Parser(prog="python -m tailsim.reports.verdict", description=__doc__.split("\n\n")[0])
    ap.add_argument("out", nargs="?", default="out", help="the run's output folder (default: out)")
    ap.add_argument(
        "--docs",
        action="store_true",
        help="rewrite the generated tables of " + ", ".join(DOCS) + " from docs/campaign_full_run.json",
    )
    ap.add_argument("--check", action="store_true", help="with --docs: only check they are up to date (exit 1 if not)")
    a = ap.parse_args(argv)
    if a.check and not a.docs:
        ap.error("argument --check: only with --docs")

    def run() -> int:
        if a.docs:
            stale = regenerate(write=not a.check)
            for f in stale:
                print(f"{f}: {'stale' if a.check else 'rewritten'} (docs/campaign_full_run.json)", file=sys.stderr)
            return 1 if a.check and stale else 0
        print(text(collect(a.out)))
        return 0

    return cli.guard(ap.prog, a.debug, run)


if __name__ == "__main__":
    raise SystemExit(main())
