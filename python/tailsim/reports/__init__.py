"""The reports: the comparison product (`compare`: missions, step tests, Markdown and
HTML), the analysis report (`analysis`, with `aero`, `envelope`, `hover`, `takeoff`
sections and `analysis_plots`), the avionics section (`avionics`), the Markdown /
HTML helpers (`markdown`) and the generated figures of the documentation (`docs`)."""

from __future__ import annotations

import json
import pathlib


def load_json_into(d: dict, folder: str | pathlib.Path, file: str, key: str) -> dict:
    """Add the JSON `file` of `folder` (if it was written) to the report data `d` as `d[key]`."""
    path = pathlib.Path(folder) / file
    if path.exists():
        d[key] = json.loads(path.read_text())
    return d
