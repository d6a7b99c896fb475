"""The documentation's figures stay true: every generated block of docs/*.md is the one
`python -m tailsim.reports.docs --write` produces from the committed result files now, and
a measured figure typed by hand outside a generated or history block fails the scan."""

from __future__ import annotations

import json
import pathlib
import shutil

import pytest

from tailsim.reports import docs, docs_blocks, docs_wind

ROOT = pathlib.Path(__file__).resolve().parent.parent


def copy_docs(tmp_path: pathlib.Path) -> pathlib.Path:
    shutil.copytree(ROOT / "docs", tmp_path / "docs")
    return tmp_path


def test_generated_blocks_match_the_result_files():
    stale = docs.regenerate(ROOT, write=False)
    assert stale == [], f"{stale}: run `python -m tailsim.reports.docs --write`"
    assert docs.main(["--check"]) == 0


def test_every_block_has_a_generator_and_every_generator_a_block():
    used = {k for p in docs.doc_files() for k in docs.keys_in(p.read_text())}
    assert used, "no generated block in docs/"
    assert {k for k in used if not k.startswith("def.")} == set(docs.BLOCKS)
    for k in used:
        docs.render(k, docs.Sources())  # resolves (a definition that is not declared raises)


def test_a_changed_result_file_or_a_hand_edit_is_found(tmp_path):
    root = copy_docs(tmp_path)
    assert docs.regenerate(root, write=False) == []
    full = json.loads((ROOT / "docs" / docs_blocks.FULL).read_text())
    full["arms"]["tsd/tuned/perfect"]["p"] = 0.5
    assert docs.regenerate(root, write=False, override={docs_blocks.FULL: full}) == ["docs/CAMPAIGN.md"]
    # the reading now says so, and a rewrite makes the check pass again
    assert docs.regenerate(root, override={docs_blocks.FULL: full}) == ["docs/CAMPAIGN.md"]
    reading = (root / "docs" / "CAMPAIGN.md").read_text()
    assert "the tuned TSD completes 50 %" in reading or "the tuned TSD 50 %" in reading
    assert docs.regenerate(root, write=False, override={docs_blocks.FULL: full}) == []
    # a figure edited by hand inside a block
    thesis = root / "docs" / "THESIS.md"
    text = thesis.read_text()
    body = docs.BLOCK_RE.search(text)
    thesis.write_text(text[: body.start("body")] + body["body"].replace("0", "9", 1) + text[body.end("body") :])
    assert docs.regenerate(root, write=False, override={docs_blocks.FULL: full}) == ["docs/THESIS.md"]


def test_no_hand_typed_measured_figure_outside_the_blocks():
    bad = docs.untagged(ROOT)
    assert bad == [], (
        "figures typed by hand in docs/ (generate them: tailsim.reports.docs; or label a dated record "
        "<!-- history: … -->; a definition goes into docs/figures_allowed.json):\n" + "\n".join(bad)
    )


def test_the_allow_list_is_exact():
    assert docs.slack(ROOT) == [], "remove these entries from docs/figures_allowed.json"
    kinds = {k for f in json.loads((ROOT / "docs" / "figures_allowed.json").read_text())["files"].values() for k in f}
    for k in kinds - set(docs.ALLOWED_KINDS):
        assert k.startswith(docs.CHECKED) and (ROOT / "docs" / k[len(docs.CHECKED) :]).exists(), k


def test_quoted_figures_agree_with_the_committed_outputs():
    """A figure quoted by hand from a committed output (the thesis_switches examples) is one of
    its numbers, as rounded in the text: after the output is re-run, a changed figure fails."""
    assert docs.checked_mismatches(ROOT) == []
    assert docs.matches("8.1 m", [8.06]) and docs.matches("−1.38 g", [-1.3827])
    assert not docs.matches("5.69 m", [5.70]) and not docs.matches("3.0°", [3.06])


def test_a_changed_output_fails_the_quoted_figures(tmp_path):
    root = copy_docs(tmp_path)
    p = root / "docs" / "thesis_switches_tsd.txt"
    assert docs.checked_mismatches(root) == []
    p.write_text(p.read_text().replace("| 6.74 / 6.74 / 32.2 / no |", "| 6.90 / 6.90 / 32.2 / no |"))
    assert docs.checked_mismatches(root) == ["docs/THESIS.md: 6.74 m not in thesis_switches_tsd.txt"]


def test_a_new_hand_typed_figure_fails(tmp_path):
    root = copy_docs(tmp_path)
    assert docs.untagged(root) == []
    p = root / "docs" / "USAGE.md"
    p.write_text(p.read_text() + "\nThe TSD now flies the mission within 0.41 m, 12 % better, in 3.5 s.\n")
    bad = docs.untagged(root)
    assert [b.split(": ", 1)[1] for b in bad] == ["0.41 m", "12 %", "3.5 s"], bad


@pytest.mark.parametrize(
    ("text", "found"),
    [
        ("max error 0.39 m at 12° and 2.3e-14 m", ["0.39 m", "12°", "2.3e-14 m"]),
        ("(4.2.17), Table 5.1, §4.2.2, App. D.1, D-4.27, O-17, FMI 2.0, glibc 2.17", []),
        ("`--samples 200` in `c1000`, t_transition_1, two controllers, 5 phases", []),
        ("<!-- generated:x -->0.787<!-- /generated --> and <!-- history: d -->0.5 s<!-- /history -->", []),
        ("```\n1.25 m\n```\n    3.5 s indented\n", []),
        ("787 of 1000 runs", ["787", "1000"]),
    ],
)
def test_the_scan_finds_measured_figures_and_skips_references(text, found):
    assert [t for _, t in docs.figures(text)] == found


def test_definitions_follow_the_declarations():
    from tailsim import declarations
    from tailsim.campaign.sampling import CampaignSpec

    m = declarations.MISSION_DEFAULTS
    assert docs_blocks.definition("def.mission.t_level") == f"{m['t_level']:g} s"
    assert docs_blocks.definition("def.mission.v_vertical") == f"{m['v_vertical']:g} m/s"
    assert docs_blocks.definition("def.limits.deflection") == "25°"  # 0.4363… rad, shown in degrees
    assert docs_blocks.definition("def.campaign.error_limit_m") == f"{CampaignSpec().error_limit_m:g} m"
    assert docs_blocks.definition("def.campaign.turbulence_max.value") == str(CampaignSpec().turbulence_max)
    with pytest.raises(KeyError):
        docs_blocks.definition("def.nowhere.x")


def test_result_files_record_their_command():
    repro = json.loads((ROOT / "docs" / docs_blocks.REPRO).read_text())
    assert "analysis -- reproduction" in repro["command"]
    campaign = (ROOT / "docs" / "CAMPAIGN.md").read_text()
    for name in (docs_blocks.FULL, docs_blocks.RERUN):
        assert f"tailsim.campaign.section --write docs/{name}" in " ".join(campaign.split()), name
    trims = json.loads((ROOT / "docs" / "design_trims.json").read_text())
    assert "--example design_trims -- docs/design_trims.json" in trims["command"]
    wind = json.loads((ROOT / "docs" / docs_wind.WIND).read_text())
    assert wind["command"] == docs_wind.COMMAND and "wind-envelope --all" in wind["command"]
    oms = json.loads((ROOT / "docs" / "omsimulator_run.json").read_text())
    assert oms["command"].startswith("python scripts/omsimulator.py") and oms["commit"] in oms["omsimulator"]


def test_history_documents_are_labelled():
    for rel in docs.HISTORY_FILES:
        head = (ROOT / rel).read_text().split("\n\n", 2)[1]
        assert "history" in head.lower() and "not regenerated" in head, head


def test_inventory_counts_every_figure():
    inv = docs.inventory(ROOT)
    assert set(inv) == {docs.rel_of(p) for p in docs.scanned_files()}
    assert all(c["untagged"] == 0 for c in inv.values()), inv
    assert sum(c["generated"] for c in inv.values()) > 0
    assert inv["docs/PERFORMANCE.md"]["history"] > 0 and inv["docs/PERFORMANCE.md"]["pending"] == 0


def test_markers_leave_the_markdown_intact():
    """A line that starts with an HTML comment is an HTML block to CommonMark (GitHub): the rest of
    the line would be shown raw. Markers at the start of a line therefore stand alone on it."""
    import re

    for p in sorted(set(docs.doc_files()) | set(docs.scanned_files())):
        for n, line in enumerate(p.read_text().splitlines(), 1):
            # also inside a list item: its content must not start with a marker either
            m = re.match(r"\s*(?:[*-] |\d+\. )?<!--.*?-->", line)
            assert not m or m.end() == len(line.rstrip()), f"{docs.rel_of(p)}:{n}: {line[:80]}"


def test_the_omsimulator_page_follows_its_run_record(tmp_path):
    """docs/OMSIMULATOR.md's figures come from docs/omsimulator_run.json (scripts/omsimulator.py):
    a changed run changes the page, and the avionics paragraph says whether the two masters'
    initialisations agree from the recorded distances, not from a fixed text."""
    from tailsim.reports import docs_omsimulator

    run = json.loads((ROOT / "docs" / docs_omsimulator.RUN).read_text())
    src = docs.Sources(ROOT)
    assert run["command"] in docs.render("omsim.run.intro", src)
    assert run["commit"] in docs.render("omsim.run.intro", src)
    table = docs.render("omsim.run.table", src)
    assert len([r for r in table.splitlines() if r.startswith("| `")]) == len(run["runs"])

    def with_distance(d: float) -> dict:
        out = json.loads(json.dumps(run))
        for r in out["runs"]:
            if r["ssp"].endswith("_avionics.ssp"):
                r["max_position_distance_m"] = d
                r["initial"] = {"controller.thrust_cmd": 88.0, "estimator.thrust": 80.0, "plant.thrust": 88.0}
        return out

    same = docs.render("omsim.initialisation", docs.Sources(ROOT, {docs_omsimulator.RUN: with_distance(1e-12)}))
    differ = docs.render("omsim.initialisation", docs.Sources(ROOT, {docs_omsimulator.RUN: with_distance(0.5)}))
    assert same.startswith("Both masters") and "apart" not in same
    assert "8.0 N apart" in differ and "0.50 m away" in differ
    root = copy_docs(tmp_path)
    assert docs.regenerate(root, write=False) == []
    moved = json.loads(json.dumps(run))
    moved["runs"][0]["max_pos_error_m"] += 0.01
    assert docs.regenerate(root, write=False, override={docs_omsimulator.RUN: moved}) == ["docs/OMSIMULATOR.md"]


# --- the crates' and FMUs' READMEs ----------------------------------------------------------------------------------


def copy_with_readmes(tmp_path: pathlib.Path, *readmes: str) -> pathlib.Path:
    root = copy_docs(tmp_path)
    for rel in readmes:
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / rel, root / rel)
    return root


def test_the_scan_reads_the_crate_and_fmu_readmes():
    scanned = {docs.rel_of(p) for p in docs.scanned_files()}
    readmes = {docs.rel_of(p) for g in ("crates/*/README.md", "fmu-*/README.md") for p in ROOT.glob(g)}
    assert {"crates/guidance/README.md", "crates/state-estimator/README.md", "fmu-plant/README.md"} <= scanned
    assert readmes - scanned == set(docs.SCAN_LATER), "a README outside the scan that SCAN_LATER does not name"
    assert all(f"docs/{p.name}" in scanned for p in (ROOT / "docs").glob("*.md"))


def test_a_hand_typed_figure_in_a_crate_readme_fails(tmp_path):
    rel = "crates/guidance/README.md"
    root = copy_with_readmes(tmp_path, rel)
    assert docs.untagged(root) == []
    p = root / rel
    p.write_text(p.read_text() + "\nThe fast mission now rotates in 1.71 s with 0.38 m of error.\n")
    assert [b.split(": ", 1)[1] for b in docs.untagged(root)] == ["1.71 s", "0.38 m"]
    # a dated record is not a hand-typed figure
    p.write_text(
        p.read_text().replace("The fast mission now", "<!-- history: 2026-11-27, a note -->The fast mission now")
    )
    p.write_text(p.read_text().replace("of error.", "of error.<!-- /history -->"))
    assert docs.untagged(root) == []


def test_scanned_readmes_carry_no_issue_numbers():
    import re

    for p in (p for p in docs.scanned_files() if p.name == "README.md"):
        found = re.findall(r"\bissues?\s*#?\d+", p.read_text(), flags=re.I)
        assert not found, f"{docs.rel_of(p)}: {found} (a README states the design and its results; history goes to git)"


# --- the wind envelope --------------------------------------------------------------------------------------------


def _cell(controller, mission, wind, speed, bearing, held, completed=None, failure=None, error=1.0, **axes):
    completed = held if completed is None else completed
    return {
        "controller": controller,
        "configuration": axes.get("configuration", "tuned"),
        "state": axes.get("state", "perfect"),
        "ordering": axes.get("ordering", "gauss-seidel"),
        "mission": mission,
        "wind": wind,
        "speed": speed,
        "bearing_deg": bearing,
        "completed": completed,
        "held": held,
        "failure": failure,
        "max_error": error,
        "landing_passed": (held if mission == "takeoff_landing" else None),
    }


def synthetic_envelope() -> dict:
    """Two controllers, two speeds, two bearings: LQR holds everything but the 5 m/s
    step from 90° (lost); TSD completes every cell, beyond the limit at 5 m/s."""
    cells = []
    for k in ("LQR", "TSD"):
        for mission in ("default", "takeoff_landing"):
            for speed in (0.0, 5.0):
                for b in (0.0, 90.0):
                    if k == "LQR" and speed == 5.0 and b == 90.0:
                        c = _cell(
                            k, mission, "step", speed, b, False, failure="lost: 51 m from the reference", error=51.2
                        )
                    elif k == "TSD" and speed == 5.0:
                        c = _cell(k, mission, "step", speed, b, False, completed=True, error=3.44)
                    else:
                        c = _cell(k, mission, "step", speed, b, True, error=0.5 + speed / 10 + b / 1000)
                    cells.append(c)
    cells.append(
        _cell(
            "LQR", "default", "step", 0.0, 0.0, False, failure="plant: state not finite", error=None, state="avionics"
        )
    )
    return {
        "speeds": [0.0, 5.0],
        "bearings_deg": [0.0, 90.0],
        "step_time": 2.0,
        "held_max_error": 3.0,
        "held_max_error_avionics": 5.0,
        "turbulence_intensity": 2,
        "wall_time_s": 12.0,
        "cpu_time_s": 11.0,
        "flown": 17,
        "from_cache": 0,
        "threads": 1,
        "cells": cells,
    }


def test_the_wind_envelope_summary_of_a_synthetic_file():
    w = docs_wind.summarize(synthetic_envelope(), "the command", "abc1234")
    assert json.loads(docs_wind.dumps(w)) == w
    row = next(r for r in w["rows"] if (r["controller"], r["mission"], r["speed"]) == ("LQR", "default", 5.0))
    assert (row["cells"], row["held"], row["completed"], row["status"]) == (2, 1, 1, "HL")
    assert (row["error_min"], row["error_max"], row["errors"]) == (1.0, 1.0, [1.0, 51.2])
    assert row["landing_passed"] is None
    landing = next(
        r for r in w["rows"] if (r["controller"], r["mission"], r["speed"]) == ("TSD", "takeoff_landing", 5.0)
    )
    assert (landing["status"], landing["landing_passed"], landing["error_max"]) == ("CC", 0, 3.44)
    avionics = next(r for r in w["rows"] if r["state"] == "avionics")
    assert (avionics["status"], avionics["errors"], avionics["error_min"]) == ("F", [None], None)
    src = docs.Sources(ROOT, {docs_wind.WIND: w})
    table = docs.render("wind.tables", src)
    assert "| default mission | step | 2/2, 0.5–0.6 m | 1/2, 1.0 m, 1L | – | 0 m/s (3/4) |" in table
    assert "| take-off to landing | step | 2/2, 0.5–0.6 m | 0/2, 3.4 m | 2/4 | 0 m/s (2/4) |" in table
    assert docs.render("wind.readme", src) == (
        "held = completed within 3 m of its own reference and of its still-air path (perfect state, Gauss-Seidel); "
        "the wind stepping in: LQR 0 m/s / 0 m/s, TSD 0 m/s / 0 m/s"
    )
    axes = docs.render("wind.axes", src)
    assert "| LQR | tuned | avionics | Gauss-Seidel | none (0/1) | – |" in axes
    # a cell that names no axis (a file of one grid) is on the main one
    bare = {
        k: v for k, v in synthetic_envelope()["cells"][0].items() if k not in ("configuration", "state", "ordering")
    }
    one = docs_wind.summarize({**synthetic_envelope(), "cells": [bare]})["rows"]
    assert [tuple(r[k] for k in ("configuration", "state", "ordering")) for r in one] == [docs_wind.MAIN_AXIS]
    # every row at a speed counts: a calm turbulent row not held means none
    calm = [
        {"speed": 0.0, "held": 8, "cells": 8},
        {"speed": 0.0, "held": 3, "cells": 8},
        {"speed": 3.0, "held": 8, "cells": 8},
    ]
    assert docs_wind.reach(calm) is None and docs_wind.reach(calm[::2]) == 3.0
    run = docs.render("wind.run", src)
    assert run.startswith("17 flights: wind speeds 0, 5 m/s from 2 bearings") and "commit abc1234" in run


def test_a_stale_wind_envelope_block_is_found(tmp_path):
    """A changed wind-envelope file makes every block that quotes it stale: docs/WIND.md, the
    README's wind sentence, the controllers' READMEs' last section."""
    readmes = ("README.md", "crates/lqr-control/README.md", "crates/tsd-control/README.md")
    root = copy_with_readmes(tmp_path, *readmes)
    assert docs.regenerate(root, write=False) == []
    w = json.loads((ROOT / "docs" / docs_wind.WIND).read_text())
    row = next(
        r
        for r in w["rows"]
        if r["controller"] == "LQR"
        and tuple(r[k] for k in ("configuration", "state", "ordering")) == docs_wind.MAIN_AXIS
    )
    row["held"] = row["cells"] - 1 if row["held"] == row["cells"] else row["cells"]
    stale = docs.regenerate(root, write=False, override={docs_wind.WIND: w})
    assert {"docs/WIND.md", "crates/lqr-control/README.md"} <= set(stale), stale
    assert "crates/tsd-control/README.md" not in stale
    # the block is rewritten from the file, and a hand edit inside it is found
    assert docs.regenerate(root, override={docs_wind.WIND: w}) == stale
    assert docs.regenerate(root, write=False, override={docs_wind.WIND: w}) == []
    p = root / "crates/tsd-control/README.md"
    body = next(m for m in docs.BLOCK_RE.finditer(p.read_text()) if m["key"] == "wind.tsd")
    text = p.read_text()
    p.write_text(text[: body.start("body")] + body["body"].replace("/8", "/9", 1) + text[body.end("body") :])
    assert docs.regenerate(root, write=False, override={docs_wind.WIND: w}) == ["crates/tsd-control/README.md"]


# --- labelling a document for the scan ------------------------------------------------------------------------------


def test_labelling_records_and_definitions(tmp_path):
    """`docs_label` wraps measured lines in dated records that keep the Markdown intact (marker
    lines around a paragraph, inline markers in a list item) and allow-lists what is left."""
    from tailsim.reports import docs_label

    text = "# x\n\nMeasured: 1.23 m\nin 4.5 s.\n\n* **Item** — flew 6.7 m\n  and 8.9 s.\n\nA limit of 25°.\n"
    para = docs_label.record_lines(text, 3, 4, "a test", "2026-11-27")
    assert para.split("\n")[2:6] == [
        "<!-- history: 2026-11-27, a test -->",
        "Measured: 1.23 m",
        "in 4.5 s.",
        "<!-- /history -->",
    ]
    item = docs_label.record_lines(para, 8, 9, "a test", "2026-11-27")
    assert "* **Item** — flew <!-- history: 2026-11-27, a test -->6.7 m" in item
    assert "  and 8.9 s.<!-- /history -->" in item
    assert [t for _, t in docs.figures(item)] == ["25°"]
    inline = docs_label.record_text(text, "flew 6.7 m", "a test", "2026-11-27")
    assert [t for _, t in docs.figures(inline)] == ["1.23 m", "4.5 s", "8.9 s", "25°"]
    with pytest.raises(ValueError):
        docs_label.record_text(text, "m", "a test", "2026-11-27")
    # a text at a line's start: the opening marker ends the line before (never starts a line)
    cont = docs_label.record_text(text, "in 4.5 s.", "a test", "2026-11-27")
    assert "Measured: 1.23 m<!-- history: 2026-11-27, a test -->\nin 4.5 s.<!-- /history -->" in cont
    for starts in ("Measured: 1.23 m", "**Item** — flew"):
        with pytest.raises(ValueError):
            docs_label.record_text(text, starts, "a test", "2026-11-27")
    with pytest.raises(ValueError):
        docs_label.record_lines(text, 3, 4, "no --> inside", "2026-11-27")
    # the definitions left, allow-listed: the scan then passes on the document
    root = copy_docs(tmp_path)
    (root / "NOTE.md").write_text(item)
    assert docs_label.refused(root, "NOTE.md") == [(11, "25°")]
    assert docs_label.add_definitions(root, "NOTE.md") == ["25°"]
    assert docs_label.refused(root, "NOTE.md") == []
