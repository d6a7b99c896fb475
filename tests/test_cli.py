"""The command lines refuse bad input before any work: exit code 2 and one line on stderr
naming the option and the value (no traceback); an unexpected error is one line and exit
code 1, its traceback only with --debug. Each CLI runs as a subprocess, as a user runs it."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import sys
import time
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
COMPARE = "tailsim.reports.compare"
CAMPAIGN = "tailsim.campaign"
ANALYSIS_REPORT = "tailsim.reports.analysis"


def run(module: str, *args: str, cwd: pathlib.Path = ROOT, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", module, *args], cwd=cwd, capture_output=True, text=True, timeout=timeout
    )


def assert_refused(p: subprocess.CompletedProcess, *words: str, code: int = 2) -> str:
    """Exit code `code`, nothing on stdout, one line on stderr containing every word, no traceback."""
    assert p.returncode == code, (p.returncode, p.stdout, p.stderr)
    assert "Traceback" not in p.stderr and "Traceback" not in p.stdout, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


@pytest.mark.parametrize("value", ["-1", "0", "5000", "nan", "inf", "abc"])
@pytest.mark.parametrize("option", ["--fast-t1", "--fast-t2"])
def test_compare_refuses_transition_times_outside_the_declared_range(option, value, tmp_path):
    line = assert_refused(run(COMPARE, option, value, "--out", str(tmp_path / "out")), option, value)
    if value in ("-1", "0", "5000"):
        assert "outside [0.5, 1000]" in line
    assert not (tmp_path / "out").exists(), "nothing written before the options are checked"


def test_compare_refuses_an_unknown_controller():
    assert_refused(run(COMPARE, "--controller", "pid"), "--controller", "pid", "lqr")


def test_compare_refuses_a_missing_dist_with_the_build_hint(tmp_path):
    missing = tmp_path / "dist"
    assert_refused(run(COMPARE, "--dist", str(missing)), "--dist", str(missing), "cargo xtask dist")


def test_compare_and_campaign_refuse_a_corrupt_fmu_naming_the_file(tmp_path):
    dist = tmp_path / "dist"
    dist.mkdir()
    for name in ("tailsitter_plant", "tailsitter_lqr", "tailsitter_tsd", "tailsitter_sensors", "tailsitter_ekf"):
        (dist / f"{name}.fmu").write_bytes(b"not a zip archive")
    bad = str(dist / "tailsitter_plant.fmu")
    assert_refused(run(COMPARE, "--dist", str(dist)), "--dist", bad, "cargo xtask dist")
    assert_refused(run(CAMPAIGN, "--dist", str(dist), "--out", str(tmp_path / "c")), "--dist", bad)
    # A zip archive without a modelDescription.xml is no FMU either.
    with zipfile.ZipFile(dist / "tailsitter_plant.fmu", "w") as z:
        z.writestr("readme.txt", "hello")
    assert_refused(run(COMPARE, "--dist", str(dist)), "--dist", bad, "modelDescription.xml")


def test_compare_refuses_a_missing_controller_fmu(tmp_path):
    if not (DIST / "tailsitter_plant.fmu").exists():
        pytest.skip("dist/ not built")
    dist = tmp_path / "dist"
    dist.mkdir()
    shutil.copy(DIST / "tailsitter_plant.fmu", dist)
    assert_refused(
        run(COMPARE, "--dist", str(dist), "--controller", "lqr", "--no-avionics"),
        "--dist",
        str(dist / "tailsitter_lqr.fmu"),
        "missing",
    )


def test_an_unexpected_error_is_one_line_and_exit_1_its_traceback_with_debug(tmp_path):
    if not (DIST / "tailsitter_plant.fmu").exists():
        pytest.skip("dist/ not built")
    blocker = tmp_path / "file"
    blocker.write_text("")
    out = str(blocker / "out")  # under a file: cannot be created
    assert_refused(run(COMPARE, "--out", out, "--no-steps"), "--debug", code=1)
    p = run(COMPARE, "--out", out, "--no-steps", "--debug")
    assert p.returncode == 1 and "Traceback" in p.stderr


@pytest.mark.parametrize(
    ("option", "value", "allowed"),
    [
        ("--samples", "0", "≥ 1"),
        ("--samples", "-3", "≥ 1"),
        ("--samples", "2.5", "whole number"),
        ("--seed", "-1", "≥ 0"),
        ("--wind-max", "-5", "[0, 100]"),
        ("--wind-max", "nan", "finite"),
        ("--gust-max", "1e6", "[0, 100]"),
        ("--tau-aero", "0.5", "≥ 1"),
        ("--tau-mass", "inf", "finite"),
        ("--timeout", "0", "> 0"),
        ("--workers", "0", "≥ 1"),
        ("--controllers", "lqr,pid", "lqr, px4, tsd"),
        ("--controllers", "lqr,lqr", "repeated"),
        ("--configurations", "fancy", "tuned, thesis"),
        ("--state-sources", "psychic", "perfect, avionics"),
        ("--mission", "long", "default"),
        ("--aero-model", "2", "0"),
        ("--scheduler", "nowhere", "HOST:PORT"),
    ],
)
def test_campaign_refuses_bad_options_before_any_work(option, value, allowed, tmp_path):
    out = tmp_path / "campaign"
    assert_refused(run(CAMPAIGN, option, value, "--out", str(out), "--no-progress"), option, value, allowed)
    assert not out.exists(), "nothing written before the options are checked"


def test_campaign_refuses_a_missing_dist_and_an_empty_report_only_folder(tmp_path):
    missing = tmp_path / "dist"
    assert_refused(
        run(CAMPAIGN, "--dist", str(missing), "--out", str(tmp_path / "c")), "--dist", str(missing), "cargo xtask dist"
    )
    assert_refused(run(CAMPAIGN, "--report-only", "--out", str(tmp_path)), "--out", str(tmp_path), "campaign.json")


def test_analysis_report_refuses_a_folder_without_data_and_reports_bad_data_in_one_line(tmp_path):
    assert_refused(run(ANALYSIS_REPORT, str(tmp_path / "none")), str(tmp_path / "none"), "report.json")
    (tmp_path / "report.json").write_text("{not json")
    assert_refused(run(ANALYSIS_REPORT, str(tmp_path), "--no-plots"), "JSONDecodeError", code=1)


def test_main_sh_help_prints_usage_without_setting_up_or_building():
    for flag in ("--help", "-h"):
        t0 = time.monotonic()
        p = subprocess.run(
            ["bash", str(ROOT / "scripts" / "main.sh"), flag], capture_output=True, text=True, timeout=10
        )
        assert time.monotonic() - t0 < 5
        assert p.returncode == 0, p.stderr
        assert p.stdout.startswith("usage: scripts/main.sh") and "--no-analysis" in p.stdout
        assert "==" not in p.stdout + p.stderr, "no set-up or build step ran"


def test_main_sh_checks_runner_options_before_building():
    if not (ROOT / ".venv" / "bin" / "python").exists():
        pytest.skip("no .venv: main.sh checks the options after setting it up")
    t0 = time.monotonic()
    p = subprocess.run(
        ["bash", str(ROOT / "scripts" / "main.sh"), "--fast-t1", "-1"], capture_output=True, text=True, timeout=60
    )
    assert time.monotonic() - t0 < 30
    assert_refused(p, "--fast-t1", "-1", "outside [0.5, 1000]")


def _analysis_binary() -> pathlib.Path:
    """The built analysis CLI (release or debug), if newer than its source."""
    src = ROOT / "crates" / "analysis" / "src" / "main.rs"
    exe = "analysis.exe" if os.name == "nt" else "analysis"
    built = [p for p in (ROOT / "target" / d / exe for d in ("release", "debug")) if p.exists()]
    built = [p for p in built if p.stat().st_mtime >= src.stat().st_mtime]
    if not built:
        pytest.skip("no up-to-date target/*/analysis (the Rust tests of crates/analysis check the same)")
    return max(built, key=lambda p: p.stat().st_mtime)


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["linear", "--params", "XYZ"], ["--params", "XYZ", "CLa", "Iz"]),
        (["all", "--params", "CLa,nope"], ["--params", "nope", "known ids"]),
        (["linear", "--n", "0"], ["--n", "'0'", "≥ 2"]),
        (["linear", "--n", "1"], ["--n", "'1'", "≥ 2"]),
        (["all", "--max-gust", "0"], ["--max-gust", "'0'"]),
        (["all", "--wide-tau-power", "nan"], ["--wide-tau-power", "nan", "finite"]),
        (["all", "--threads", "0"], ["--threads", "'0'", "≥ 1"]),
    ],
)
def test_rust_analysis_cli_refuses_bad_options(args, words, tmp_path):
    p = subprocess.run(
        [str(_analysis_binary()), *args, "--out", str(tmp_path / "a"), "--quiet"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert p.returncode == 2, (p.returncode, p.stderr)
    first = p.stderr.strip().splitlines()[0]
    assert first.startswith("error:"), p.stderr
    for w in words:
        assert w in first, (w, first)
    assert not (tmp_path / "a").exists()


def test_campaign_section_and_native_refuse_folders_without_a_campaign(tmp_path):
    empty = str(tmp_path)
    assert_refused(run("tailsim.campaign.section", empty), empty, "campaign.json")
    assert_refused(run("tailsim.campaign.native", "--campaign", empty), "--campaign", empty, "campaign.json")
    assert_refused(run("tailsim.campaign.native", "--threads", "0"), "--threads", "0", "≥ 1")


def _checkout(tmp_path: pathlib.Path, fmu_time: float, source_time: float) -> pathlib.Path:
    """A minimal source checkout (Cargo.toml, a declaration, a crate source) with dist/m.fmu."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "Cargo.toml").write_text("[workspace]\n")
    (tmp_path / "modelDescription").mkdir()
    decl = tmp_path / "modelDescription" / "m.json"
    decl.write_text("{}")
    src = tmp_path / "crates" / "c" / "src" / "lib.rs"
    src.parent.mkdir(parents=True)
    src.write_text("")
    dist = tmp_path / "dist"
    dist.mkdir()
    fmu = dist / "m.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", "<fmiModelDescription/>")
    os.utime(decl, (source_time - 10, source_time - 10))
    os.utime(src, (source_time, source_time))
    os.utime(fmu, (fmu_time, fmu_time))
    return dist


def test_an_fmu_older_than_the_sources_is_named_with_the_newest_source(tmp_path, capsys):
    from tailsim import cli

    t = time.time()
    dist = _checkout(tmp_path, fmu_time=t - 100, source_time=t)
    lines = cli.stale_fmus(dist, ["m"], root=tmp_path)
    assert len(lines) == 1
    assert "m.fmu is older than crates/c/src/lib.rs" in lines[0] and "cargo xtask dist" in lines[0]
    # Built after the last change: nothing to say; outside a checkout: nothing to compare.
    assert cli.stale_fmus(_checkout(tmp_path / "b", fmu_time=t, source_time=t - 100), ["m"], root=tmp_path / "b") == []
    (tmp_path / "b" / "Cargo.toml").unlink()
    assert cli.stale_fmus(tmp_path / "b" / "dist", ["m"], root=tmp_path / "b") == []
    # The CLIs warn on stderr, naming the FMU, and go on.
    cli.check_fmus(cli.Parser(prog="x"), "--dist", dist, ["m"], root=tmp_path)
    err = capsys.readouterr().err
    assert err.startswith("x: warning: ") and "m.fmu is older than crates/c/src/lib.rs" in err
