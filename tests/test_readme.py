"""The README is a front door that stays true: at most 150 lines, its headline table the one
generated from the committed result file, and its Python recipes run as written."""

from __future__ import annotations

import json
import pathlib
import re
import subprocess
import sys

import pytest

from tailsim import declarations
from tailsim.reports import verdict

ROOT = pathlib.Path(__file__).resolve().parent.parent
README = ROOT / "README.md"


def blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", README.read_text(), flags=re.S | re.M)


def test_readme_is_short():
    assert len(README.read_text().splitlines()) <= 150


def test_generated_tables_match_the_committed_full_run():
    """The README's headline table and docs/CAMPAIGN.md's full-run tables are the ones
    generated from docs/campaign_full_run.json."""
    stale = verdict.regenerate(ROOT, write=False)
    assert stale == [], f"{stale}: run `python -m tailsim.reports.verdict --docs`"
    assert verdict.main(["--docs", "--check"]) == 0
    summary = json.loads(verdict.FULL_RUN.read_text())
    for file, (name, make) in verdict.DOCS.items():
        begin, end = verdict.markers(name)
        text = (ROOT / file).read_text()
        assert text[text.index(begin) + len(begin) : text.index(end)].strip() == "\n".join(make(summary)).strip()


def test_a_changed_figure_is_found(tmp_path):
    """A figure edited by hand in a generated block, or a result file that changed, is found."""
    for file in verdict.DOCS:
        (tmp_path / file).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / file).write_text((ROOT / file).read_text())
    summary = json.loads(verdict.FULL_RUN.read_text())
    assert verdict.regenerate(tmp_path, summary, write=False) == []
    arm = next(iter(summary["arms"].values()))
    arm["p"] += 0.001
    assert verdict.regenerate(tmp_path, summary, write=False) == list(verdict.DOCS)
    assert verdict.regenerate(tmp_path, summary) == list(verdict.DOCS)
    assert verdict.regenerate(tmp_path, summary, write=False) == []


def test_readme_documents_every_initial_condition_and_the_angle_unit():
    text = " ".join(README.read_text().split())
    v = declarations.VARIABLES["tailsitter_plant"]["initial_condition"]
    para = text[text.index("`initial_condition` = ") :][:400]
    for value in range(int(v.min), int(v.max) + 1):
        assert re.search(rf"(= |, ){value} (starts|in|at)", para), (value, para)
    assert "every angle in the FMUs is in radians" in text


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_readme_recipe_runs_as_written(index):
    """Each Python block of the README, run from the checkout as a user would (a fresh
    interpreter, the packaged FMUs in dist/)."""
    code = blocks("python")[index]
    if not (ROOT / "dist" / "tailsitter_plant.fmu").exists():
        pytest.fail("dist/ missing: run `cargo xtask dist` first")
    p = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip()
    for change in re.findall(r"height change ([+-][0-9.]+) m in 10 s", p.stdout):
        assert abs(float(change)) < 0.05, p.stdout  # the trim holds when its commands are fed
    for err in re.findall(r"largest position error ([0-9.]+) m", p.stdout):
        assert float(err) < 50.0, p.stdout  # flew the mission to its end without diverging
