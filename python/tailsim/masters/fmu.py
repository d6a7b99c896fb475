"""An extracted FMU (`Fmu`), the record of a run (`RunResult`) and measures of a run."""

from __future__ import annotations

import math
import pathlib
import shutil
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from .. import fmilog


class Fmu:
    """An FMU extracted once; `instantiate` gives fresh fmpy slaves of it."""

    def __init__(self, path: str | pathlib.Path, workdir: str | pathlib.Path | None = None):
        self.path = pathlib.Path(path)
        self.md = read_model_description(str(self.path))
        self._tmp = None if workdir else tempfile.mkdtemp(prefix="tailsim-")
        target = pathlib.Path(workdir or self._tmp) / self.md.coSimulation.modelIdentifier
        self.dir = extract(str(self.path), unzipdir=str(target))
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.identifier = self.md.coSimulation.modelIdentifier

    def start(self, name: str) -> float:
        """The declared start value of variable `name` (its default, from modelDescription.xml)."""
        v = self.variables[name]
        if v.start is None:
            raise KeyError(f"{self.identifier}: variable '{name}' declares no start value")
        return float(v.start)

    def starts(self, names: list[str]) -> dict[str, float]:
        """Declared start values of `names`."""
        return {n: self.start(n) for n in names}

    def names(self, causality: str) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == causality]

    def instantiate(self, name: str, callbacks=None) -> FMU2Slave:
        slave = FMU2Slave(
            guid=self.md.guid, unzipDirectory=self.dir, modelIdentifier=self.identifier, instanceName=name
        )
        # fmilog's callbacks, not fmpy's defaults: fmpy's logger proxy may point at a logger
        # some earlier fmpy call freed (see fmilog).
        slave.instantiate(callbacks=fmilog.callbacks() if callbacks is None else callbacks)
        return slave

    def set(self, slave: FMU2Slave, values: Mapping[str, float | int | bool]) -> None:
        """Set values by name, each through the setter of its declared type."""
        by_type: dict[str, tuple[list[int], list]] = {}
        for name, value in values.items():
            if name not in self.variables:
                raise KeyError(f"{self.identifier} has no variable '{name}'")
            v = self.variables[name]
            vrs, vals = by_type.setdefault(v.type, ([], []))
            vrs.append(v.valueReference)
            vals.append(value)
        for type_, (vrs, vals) in by_type.items():
            if type_ == "Real":
                slave.setReal(vrs, [float(x) for x in vals])
            elif type_ == "Integer":
                slave.setInteger(vrs, [int(x) for x in vals])
            elif type_ == "Boolean":
                slave.setBoolean(vrs, [bool(x) for x in vals])
            else:
                slave.setString(vrs, [str(x) for x in vals])

    def cleanup(self) -> None:
        if self._tmp:
            shutil.rmtree(self._tmp, ignore_errors=True)


@dataclass
class RunResult:
    """Every recorded signal by name (numpy arrays over `time`) with its unit."""

    signals: dict[str, np.ndarray]
    units: dict[str, str]
    plant: str
    controller: str
    ordering: str
    wall_time_controller: float = 0.0
    wall_time_plant: float = 0.0
    steps: int = 0
    log: list[tuple[str, str, str]] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.signals[name]

    @property
    def time(self) -> np.ndarray:
        return self.signals["time"]

    def write_csv(self, path: str | pathlib.Path) -> None:
        """CSV with a header `name [unit]`."""
        names = list(self.signals)
        header = ",".join(f"{n} [{self.units.get(n, '')}]" if self.units.get(n) else n for n in names)
        data = np.column_stack([self.signals[n] for n in names])
        np.savetxt(path, data, delimiter=",", header=header, comments="", fmt="%.17g")


def phase_slices(result: RunResult) -> dict[int, np.ndarray]:
    """Boolean masks of the samples in each phase (controller's `phase` output)."""
    phase = result["phase"]
    return {k: phase == k for k in range(5)}


def pos_error(result: RunResult) -> np.ndarray:
    return np.sqrt(
        (result["pos_n"] - result["ref_pos_n"]) ** 2
        + (result["pos_e"] - result["ref_pos_e"]) ** 2
        + (result["pos_d"] - result["ref_pos_d"]) ** 2
    )


def settling_time(t: np.ndarray, error: np.ndarray, t_step: float, band: float = 0.5) -> float:
    """Time after `t_step` from which `error` stays below `band` (inf if it never does)."""
    after = t >= t_step
    te, ee = t[after], error[after]
    outside = np.nonzero(ee >= band)[0]
    if len(outside) == 0:
        return 0.0
    last = outside[-1]
    if last == len(ee) - 1:
        return math.inf
    return float(te[last + 1] - t_step)
