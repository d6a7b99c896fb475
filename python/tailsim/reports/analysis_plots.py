"""Plots of the analysis report, from the CSV files the Rust campaign
(`cargo run --release -p analysis -- all --out DIR`) wrote into DIR; called by
`python -m tailsim.reports.analysis DIR`, which renders the whole report.

Writes PNGs beside the CSVs:
  open_loop_modes.png                 open-loop poles (level, vertical), thesis Tables 3.2/3.3
  closed_loop_poles_<cond>.png        closed-loop poles of both controllers (Figs. 3.16/3.17)
  loci_<ctl>_<cond>_pitch.png         pole loci for C_mα, C_mq, C_mδe (Figs. 5.1/5.2)
  loci_<ctl>_<cond>_all.png           pole loci for every parameter of Table 5.1 (Figs. E.4–E.15)
  table_5_1.png                       regenerated Table 5.1 next to the thesis's
  robustness.png, gusts.png           nonlinear robustness ranges (per aerodynamic model) and
                                      largest survived gusts

Every title names the aerodynamic model and the configuration it shows (`setting`): the
analysis flies `Plant::new` (the thesis's linear aerodynamics, `aero_model` 0, the controllers'
design model) with the tuned controllers (`configuration` 0); the robustness sweep also the
global model (`aero_model` 1).
"""

import csv
import json
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from tailsim.reports import envelope as report_envelope  # noqa: E402

#: The plant's aerodynamic models by `aero_model`.
AERO_MODELS = {0: "thesis (linear) aerodynamics", 1: "global (post-stall) aerodynamics"}
#: The configuration of the controllers the analysis flies (crates/analysis: `configuration` 0).
CONFIGURATION = "tuned controllers (configuration 0)"


def aero(model=0) -> str:
    """`thesis (linear) aerodynamics (aero_model 0)`."""
    m = int(model)
    return f"{AERO_MODELS.get(m, 'aerodynamics')} (aero_model {m})"


def setting(model=0, controllers: bool = True) -> str:
    """The aerodynamic model and (for closed loops) the configuration, for a title."""
    return aero(model) + (f", {CONFIGURATION}" if controllers else ", open loop")


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def unique(items):
    """The distinct items, in the order they first occur."""
    return list(dict.fromkeys(items))


def save(fig, path, dpi):
    """Lay out, write and close a figure."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def splane(ax, title):
    ax.axvline(0, color="k", lw=0.5)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("Re s (1/s)")
    ax.set_ylabel("Im s (rad/s)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)


def main(out):
    out = Path(out)
    if (out / "open_loop_modes.csv").exists():
        fig, ax = plt.subplots(figsize=(6, 4.5))
        by = defaultdict(list)
        for r in rows(out / "open_loop_modes.csv"):
            by[r["condition"]].append((float(r["re"]), float(r["im"])))
        for cond, pts in by.items():
            xs = [p[0] for p in pts] + [p[0] for p in pts if p[1] > 0]
            ys = [p[1] for p in pts] + [-p[1] for p in pts if p[1] > 0]
            ax.plot(xs, ys, "x", label=cond)
        # The thesis's level-flight modes (Tables 3.2/3.3), as the campaign states them.
        thesis = [
            (m["re"], m["im"]) for m in json.loads((out / "report.json").read_text())["open_loop"]["thesis_level"]
        ]
        ax.plot([t[0] for t in thesis], [t[1] for t in thesis], "o", mfc="none", label="thesis (level)")
        splane(ax, f"Open-loop modes\n{setting(controllers=False)}")
        ax.legend(fontsize=7)
        save(fig, out / "open_loop_modes.png", 120)

    if (out / "closed_loop_poles.csv").exists():
        cl = rows(out / "closed_loop_poles.csv")
        for cond in sorted({r["condition"] for r in cl}):
            fig, ax = plt.subplots(figsize=(6, 4.5))
            for ctl, mk in (("LQR", "x"), ("TSD", "+")):
                pts = [
                    (float(r["re"]), float(r["im"])) for r in cl if r["condition"] == cond and r["controller"] == ctl
                ]
                ax.plot([p[0] for p in pts], [p[1] for p in pts], mk, label=ctl)
            splane(ax, f"Closed-loop poles, {cond} flight\n{setting()}")
            ax.legend(fontsize=7)
            save(fig, out / f"closed_loop_poles_{cond}.png", 120)

    if (out / "loci.csv").exists():
        loci = defaultdict(lambda: defaultdict(list))
        for r in rows(out / "loci.csv"):
            loci[(r["controller"], r["condition"], r["param"])][int(r["pole"])].append(
                (int(r["k"]), float(r["re"]), float(r["im"]))
            )
        combos = sorted({(c, d) for (c, d, _) in loci})
        params = unique(p for _, _, p in loci)

        def draw(ax, key, title):
            for pts in loci[key].values():
                pts.sort()
                ax.plot([p[1] for p in pts], [p[2] for p in pts], "-", lw=0.8)
                ax.plot([pts[0][1]], [pts[0][2]], "k.", ms=2)
            splane(ax, title)

        for ctl, cond in combos:
            pitch = [p for p in ("Cma", "Cmq", "Cmde") if (ctl, cond, p) in loci]
            if pitch:
                fig, axs = plt.subplots(1, len(pitch), figsize=(5 * len(pitch), 4.2))
                axs = axs if len(pitch) > 1 else [axs]
                for ax, p in zip(axs, pitch, strict=False):
                    draw(ax, (ctl, cond, p), f"{ctl} {cond}: {p} (dot = smallest factor)")
                fig.suptitle(f"Pole loci, {ctl}, {cond} flight: {setting()}", fontsize=10)
                save(fig, out / f"loci_{ctl}_{cond}_pitch.png", 110)
            ps = [p for p in params if (ctl, cond, p) in loci]
            ncol = 5
            nrow = (len(ps) + ncol - 1) // ncol
            if ps:
                fig, axs = plt.subplots(nrow, ncol, figsize=(4 * ncol, 3.4 * nrow), squeeze=False)
                for i, p in enumerate(ps):
                    draw(axs[i // ncol][i % ncol], (ctl, cond, p), f"{ctl} {cond}: {p}")
                for j in range(len(ps), nrow * ncol):
                    axs[j // ncol][j % ncol].axis("off")
                fig.suptitle(f"Pole loci, {ctl}, {cond} flight: {setting()}", fontsize=12)
                save(fig, out / f"loci_{ctl}_{cond}_all.png", 80)

    if (out / "table_5_1.csv").exists():
        t = rows(out / "table_5_1.csv")
        level = [r for r in t if r["condition"] == "level"]
        params = unique(r["param"] for r in level)
        fig, ax = plt.subplots(figsize=(12, 4.5))
        w = 0.2
        for i, (ctl, col) in enumerate((("LQR", "C0"), ("TSD", "C1"))):
            ours = {r["param"]: float(r["rms_percent"]) for r in level if r["controller"] == ctl}
            th = {r["param"]: float(r["thesis_percent"]) for r in level if r["controller"] == ctl}
            xs = range(len(params))
            ax.bar(
                [x + (2 * i - 1.5) * w for x in xs],
                [th.get(p, 0) for p in params],
                w,
                color=col,
                alpha=0.4,
                label=f"{ctl} thesis",
            )
            ax.bar(
                [x + (2 * i - 0.5) * w for x in xs], [ours.get(p, 0) for p in params], w, color=col, label=f"{ctl} ours"
            )
        ax.set_xticks(range(len(params)))
        ax.set_xticklabels(params, rotation=60, fontsize=8)
        ax.set_ylabel("RMS pole movement (% of ω_n)")
        ax.set_title(f"Table 5.1, level flight: thesis against regenerated\n{setting()}")
        ax.legend(fontsize=8)
        save(fig, out / "table_5_1.png", 110)

    if (out / "robustness.csv").exists():
        r = rows(out / "robustness.csv")
        params = unique(x["param"] for x in r)
        # One row of panels per aerodynamic model (thesis 0, global 1).
        models = sorted({x.get("aero_model", "0") for x in r})
        ctls = unique(x["controller"] for x in r)
        fig, axs = plt.subplots(
            len(models), len(ctls), figsize=(6 * len(ctls), 5 * len(models)), sharey=True, squeeze=False
        )
        for row, model in zip(axs, models, strict=False):
            for ax, ctl in zip(row, ctls, strict=False):
                for i, p in enumerate(params):
                    pts = [
                        (float(x["factor"]), x["passed"] == "true")
                        for x in r
                        if x["param"] == p and x["controller"] == ctl and x.get("aero_model", "0") == model
                    ]
                    ax.scatter([q[0] for q in pts], [i] * len(pts), c=["g" if q[1] else "r" for q in pts], s=6)
                ax.set_xscale("log")
                # Plain decimals on the log axis (matplotlib's default labels read 7×10⁻¹ within a decade).
                factors = [float(x["factor"]) for x in r]
                ticks = [
                    v for v in (0.5, 0.6, 0.7, 0.8, 0.9, 1, 1.1, 1.25, 1.5, 2) if min(factors) <= v <= max(factors)
                ]
                ax.minorticks_off()
                ax.set_xticks(ticks, [f"{v:g}" for v in ticks])
                ax.set_yticks(range(len(params)))
                ax.set_yticklabels(params, fontsize=8)
                ax.set_xlabel("scale factor (plant only)")
                ax.set_title(
                    f"{ctl}, {aero(model)}, {CONFIGURATION}:\nmission passed (green) / failed (red)", fontsize=9
                )
                ax.axvline(1, color="k", lw=0.5)
        save(fig, out / "robustness.png", 110)

    if (out / "gusts.csv").exists():
        g = rows(out / "gusts.csv")
        cases = unique((x["phase"], x["axis"]) for x in g)
        fig, ax = plt.subplots(figsize=(9, 4))
        ctls = unique(x["controller"] for x in g)
        width = 0.8 / len(ctls)
        for i, ctl in enumerate(ctls):
            best = []
            for ph, axis in cases:
                pts = sorted(
                    (float(x["amplitude"]), x["passed"] == "true")
                    for x in g
                    if x["controller"] == ctl and x["phase"] == ph and x["axis"] == axis
                )
                b = 0.0
                for a, ok in pts:
                    if not ok:
                        break
                    b = a
                best.append(b)
            ax.bar([j + (i - (len(ctls) - 1) / 2) * width for j in range(len(cases))], best, width, label=ctl)
        ax.set_xticks(range(len(cases)))
        ax.set_xticklabels([f"{p}\n{a}" for p, a in cases], fontsize=8)
        ax.set_ylabel("largest survived 1−cos gust (m/s)")
        ax.set_title(f"Largest survived gust per phase and axis\n{setting()}", fontsize=9)
        ax.legend()
        save(fig, out / "gusts.png", 110)

    report_envelope.plot(out, json.loads((out / "report.json").read_text())) if (out / "report.json").exists() else None
