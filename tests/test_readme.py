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


def test_headline_table_is_generated_from_the_committed_full_run():
    text = README.read_text()
    summary = json.loads(verdict.FULL_RUN.read_text())
    assert verdict.readme_with_headline(text, summary) == text, (
        "README's headline table differs from docs/campaign_full_run.json: "
        "run `python -m tailsim.reports.verdict --readme README.md`"
    )
    # and the check command agrees
    assert verdict.main(["--readme", str(README), "--check"]) == 0


def test_headline_check_fails_on_a_changed_figure(tmp_path):
    copy = tmp_path / "README.md"
    text = README.read_text()
    row = next(line for line in text.splitlines() if line.startswith("| tuned, perfect |"))
    copy.write_text(text.replace(row, row.replace("0.", "0.9", 1)))
    assert verdict.main(["--readme", str(copy), "--check"]) == 1


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
