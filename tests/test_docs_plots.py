"""The analysis plots name what they show: the aerodynamic model and the controllers'
configuration in every title (rendered from the tiny campaign in tests/data/analysis)."""

from __future__ import annotations

import shutil

import pytest

from fmu_util import ROOT
from tailsim.reports import analysis_plots

DATA = ROOT / "tests" / "data" / "analysis"


@pytest.fixture(scope="module")
def titles(tmp_path_factory):
    folder = shutil.copytree(DATA, tmp_path_factory.mktemp("plots") / "analysis")
    seen: dict[str, list[str]] = {}
    save = analysis_plots.save

    def spy(fig, path, dpi):
        sup = fig._suptitle.get_text() if fig._suptitle else ""
        seen[path.name] = [sup, *(ax.get_title() for ax in fig.axes if ax.get_visible() and ax.axison)]
        save(fig, path, dpi)

    analysis_plots.save = spy
    try:
        analysis_plots.main(folder)
    finally:
        analysis_plots.save = save
    return seen


def test_every_plot_is_written(titles):
    for name in ("open_loop_modes.png", "table_5_1.png", "robustness.png", "gusts.png"):
        assert name in titles
    assert any(n.startswith("closed_loop_poles_") for n in titles)
    assert any(n.startswith("loci_") for n in titles)


def test_every_title_names_the_aero_model_and_configuration(titles):
    for name, ts in titles.items():
        text = " ".join(ts)
        assert "aerodynamics (aero_model " in text, (name, ts)
        if name == "open_loop_modes.png":
            assert "open loop" in text, ts
        else:
            assert "configuration 0" in text, (name, ts)


def test_robustness_names_each_model_in_its_own_panels(titles):
    ts = titles["robustness.png"]
    models = {int(r["aero_model"]) for r in analysis_plots.rows(DATA / "robustness.csv")}
    for m in models:
        assert any(analysis_plots.aero(m) in t for t in ts), (m, ts)
    assert analysis_plots.aero(0) == "thesis (linear) aerodynamics (aero_model 0)"
    assert analysis_plots.aero(1) == "global (post-stall) aerodynamics (aero_model 1)"


def test_the_envelope_plot_names_the_aero_model_and_configuration():
    import json

    import matplotlib.pyplot as plt

    from tailsim.reports import envelope

    d = json.loads((DATA / "report.json").read_text())
    fig = envelope.figure(d)
    assert fig is not None
    text = fig.axes[0].get_title()
    plt.close(fig)
    e = d["envelope_transitions"]
    assert analysis_plots.aero(e["aero_model"]) in text, text
    assert "configuration 0" in text and "Gauss-Seidel" in text, text
    # the model is the report's, not a constant of the plot
    other = {**d, "envelope_transitions": {**e, "aero_model": 1 - int(e["aero_model"])}}
    fig = envelope.figure(other)
    assert analysis_plots.aero(1 - int(e["aero_model"])) in fig.axes[0].get_title()
    plt.close(fig)
