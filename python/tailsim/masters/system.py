"""The co-simulation engine of every Python master: a system of FMUs wired by name.

A `System` is a sequence of `Unit`s (FMU instances), `Link`s (outputs of one unit
copied to the inputs of the same names of another) and `External` inputs (functions
of time: wind, reference offset). The plant + controller loop (`ClosedLoop`), the
avionics chain (`AvionicsLoop`) and the Monte-Carlo campaign's runs are
configurations of it; timing as docs/DESIGN.md, "Ports and timing".

A unit is a *sampler* (a controller, the sensors: it steps at the communication point
t on its inputs of t, so its outputs recorded at t are its response to them) or a
*state* unit (the plant, the estimator: its outputs at t describe its state at t; it
steps after the record). One communication step at t = k h:

1. Set phase, units in sequence. Gauss-Seidel: each unit's inputs are set from the
   outputs of its sources as they are when its turn comes (a sampler earlier in the
   sequence has already stepped); Jacobi: every link is read before any unit steps,
   so each unit gets the outputs of t before the step of t (the plant flies the
   command of the previous sample). Then each unit's external inputs of t are set,
   and a sampler steps.
2. Record row k: time, the recorded outputs of every unit, the external inputs of t.
3. Step phase (k < n): the state units step over [t, t + h); units with `minor` set
   step m times with h_s = h / m, a minor sampler reading its inputs and stepping at
   every inner point (its step at t is in the set phase), a minor state unit getting
   its external inputs of each inner point.

A link's values are read before the destination's external inputs of t are set, so a
unit reads its sources' outputs as they were after their last step (the plant's
outputs at t with the wind of the previous step): the same convention for every
configuration. Initialisation: units in `init_order` leave initialisation mode one by
one, each after its parameters, the links from units already initialised and its
external inputs at 0 are set.

A run that fails (an FMI error status, a `monitor` exception) raises with the record
up to the last completed row attached as `exc.partial_result` and the time of the
failing step as `exc.t` (None when it failed in initialisation).
"""

from __future__ import annotations

import ctypes
import time as wall
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .fmu import Fmu, RunResult
from .profiles import TimeFunction

ORDERINGS = ("gauss-seidel", "jacobi")

# fmi2Real, fmi2Integer, fmi2Boolean (an int in FMI 2.0) as ctypes.
_CTYPES = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int}
_GET = {"Real": "fmi2GetReal", "Integer": "fmi2GetInteger", "Boolean": "fmi2GetBoolean"}
_SET = {"Real": "fmi2SetReal", "Integer": "fmi2SetInteger", "Boolean": "fmi2SetBoolean"}


class NonFinite(Exception):
    """A non-finite value on a link from a unit of `System.finite_sources`."""


def check_ordering(ordering: str) -> None:
    if ordering not in ORDERINGS:
        raise ValueError(f"ordering must be 'gauss-seidel' or 'jacobi', not {ordering!r}")


def wire(src: Fmu, dst: Fmu) -> list[str]:
    """Names of `dst` inputs that are `src` outputs, in `dst`'s declaration order."""
    out = set(src.names("output"))
    return [n for n in dst.names("input") if n in out]


@dataclass
class Unit:
    """One FMU instance of a system.

    name: role and instance name; params: values set in initialisation mode by name;
    sampler: steps at t before the record (else after it); minor: steps with the minor
    step h_s; record: outputs recorded (column order), each as `prefix + name` unless
    the name already starts with the prefix."""

    name: str
    fmu: Fmu
    params: Mapping[str, float | int | bool] = field(default_factory=dict)
    sampler: bool = False
    minor: bool = False
    record: Sequence[str] = ()
    prefix: str = ""

    def signal(self, name: str) -> str:
        return name if not self.prefix or name.startswith(self.prefix) else f"{self.prefix}{name}"


@dataclass
class Link:
    """Outputs `names` of unit `src` to the inputs of the same names of unit `dst`.
    Links into one unit are set in list order (a later link overrides an earlier one)."""

    src: str
    dst: str
    names: Sequence[str]


@dataclass
class External:
    """Inputs `inputs` of unit `unit` driven by `function(t)`, recorded as `signals`."""

    unit: str
    inputs: Sequence[str]
    function: TimeFunction
    signals: Sequence[str]
    unit_name: str = ""


class _Transfer:
    """A link's values of one type: read from the source into a buffer, set from it."""

    def __init__(self, type_: str, src_vrs: list[int], dst_vrs: list[int]):
        n = len(src_vrs)
        self.type, self.n = type_, n
        self.buf = (_CTYPES[type_] * n)()
        self.src = (ctypes.c_uint * n)(*src_vrs)
        self.dst = (ctypes.c_uint * n)(*dst_vrs)
        self.view = np.ctypeslib.as_array(self.buf) if type_ == "Real" else None


class _Instance:
    """A unit's slave with its prepared calls: fmpy's low-level FMI functions
    (status-checked by fmpy) bound once, on ctypes arrays prepared once."""

    def __init__(self, unit: Unit, slave):
        self.unit, self.slave, self.comp = unit, slave, slave.component
        self.get = {t: getattr(slave, f) for t, f in _GET.items()}
        self.set = {t: getattr(slave, f) for t, f in _SET.items()}
        self.do_step = slave.fmi2DoStep
        # (source name, get, source component, vrs, n, buffer, view to check or None)
        self.reads: list[tuple] = []
        self.writes: list[tuple] = []  # (set, component, vrs, n, buffer)
        self.ext: list[tuple] = []  # (external index, buffer, offset, n)
        self.inits: list[tuple] = []  # per link / external: what initialisation sets
        self.buffers: list = []
        self.records: list[tuple] = []  # (get, component, vrs, n, buffer, view or None, columns)
        self.wall = 0.0

    def step(self, t: float, h: float, clock=wall.perf_counter) -> None:
        t0 = clock()
        self.do_step(self.comp, t, h, 1)
        self.wall += clock() - t0


def _transfers(src: Fmu, dst: Fmu, names: Sequence[str]) -> list[_Transfer]:
    out = []
    for type_ in ("Real", "Integer", "Boolean"):
        sel = [n for n in names if src.variables[n].type == type_]
        if sel:
            out.append(
                _Transfer(
                    type_,
                    [src.variables[n].valueReference for n in sel],
                    [dst.variables[n].valueReference for n in sel],
                )
            )
    return out


class System:
    """Units (in Gauss-Seidel sequence), links and external inputs; see the module
    documentation. `init_order`: the order units leave initialisation mode (default:
    the sequence). `finite_sources`: units whose linked outputs must be finite (else
    `NonFinite` stops the run before the step of t). `record_order`: the order of the
    units' columns in the record (default: the sequence)."""

    def __init__(
        self,
        units: Sequence[Unit],
        links: Sequence[Link] = (),
        externals: Sequence[External] = (),
        ordering: str = "gauss-seidel",
        init_order: Sequence[str] | None = None,
        finite_sources: Sequence[str] = (),
        record_order: Sequence[str] | None = None,
    ):
        check_ordering(ordering)
        self.units = list(units)
        self.by_name = {u.name: u for u in self.units}
        if len(self.by_name) != len(self.units):
            raise ValueError("unit names must be unique")
        self.links = list(links)
        for link in self.links:
            src, dst = self.by_name[link.src].fmu, self.by_name[link.dst].fmu
            for n in link.names:
                if src.variables[n].causality != "output" or dst.variables[n].causality != "input":
                    raise ValueError(f"link {link.src}.{n} -> {link.dst}.{n} is not output -> input")
        self.externals = list(externals)
        self.ordering = ordering
        self.init_order = list(init_order or [u.name for u in self.units])
        self.finite_sources = set(finite_sources)
        self.recorded = [self.by_name[n] for n in (record_order or [u.name for u in self.units])]

    def signal_names(self) -> list[str]:
        names = ["time"]
        for u in self.recorded:
            names += [u.signal(n) for n in u.record]
        for e in self.externals:
            names += list(e.signals)
        return names

    def units_of_signals(self) -> dict[str, str]:
        """Units of the recorded Real signals (Integer and Boolean ones have none)."""
        units = {"time": "s"}
        for u in self.recorded:
            for n in u.record:
                if u.fmu.variables[n].type == "Real":
                    units[u.signal(n)] = u.fmu.variables[n].unit or ""
        for e in self.externals:
            for s in e.signals:
                units[s] = e.unit_name
        return units

    def run(
        self,
        stop_time: float,
        step_size: float,
        minor_step: float | None = None,
        callbacks=None,
        slaves: Mapping[str, object] | None = None,
        monitor: Callable[[int, float, np.ndarray], None] | None = None,
        progress: bool = False,
        description: str = "",
    ) -> RunResult:
        """Fly from 0 to `stop_time` with communication step `step_size` (the minor
        units with `minor_step`, a divisor of it). `slaves`: instances to use by unit
        name (freshly instantiated or reset; left allocated, terminated); else each
        unit is instantiated under its name and freed at the end. `monitor(k, t, row)`
        is called after each row is recorded and may raise to stop the run."""
        h = float(step_size)
        hs = float(minor_step or h)
        m = int(round(h / hs))
        if m < 1 or abs(m * hs - h) > 1e-12 * h:
            raise ValueError(f"minor step {hs} s must divide the communication step {h} s")
        hs = h / m
        n = int(round(float(stop_time) / h))
        names = self.signal_names()
        data = np.full((n + 1, len(names)), np.nan)
        owned = slaves is None
        inst: dict[str, _Instance] = {}
        k_done, t = -1, None  # t: the communication point, None in initialisation
        try:
            for u in self.units:
                s = u.fmu.instantiate(u.name, callbacks) if owned else slaves[u.name]
                inst[u.name] = _Instance(u, s)
            self._prepare(inst, names)
            self._initialise(inst)
            self._order = [inst[u.name] for u in self.units]
            self._minor = [i for i in self._order if i.unit.minor]
            self._recorded = [inst[u.name] for u in self.recorded]
            self._jacobi = self.ordering == "jacobi"
            self._functions = [e.function for e in self.externals]
            col = len(names) - sum(len(e.signals) for e in self.externals)
            self._ext_cols = []
            for e in self.externals:
                self._ext_cols.append(slice(col, col + len(e.signals)))
                col += len(e.signals)
            iterator = range(n + 1)
            if progress:
                from tqdm import tqdm

                iterator = tqdm(iterator, desc=description, unit="step", leave=False)
            for k in iterator:
                t = k * h
                self._communication_point(inst, k, t, h, hs, m, n, data, monitor)
                k_done = k
            for u in self.units:
                inst[u.name].slave.terminate()
        except Exception as exc:
            if not owned and t is not None:
                for i in inst.values():
                    try:  # instances that failed are discarded or reset by their owner
                        i.slave.terminate()
                    except Exception:  # noqa: BLE001, S110 - already failed
                        pass
            exc.partial_result = self._result(names, data[: k_done + 1], inst)
            exc.t = t
            raise
        finally:
            if owned:
                for i in inst.values():
                    try:
                        i.slave.freeInstance()
                    except Exception:  # noqa: BLE001, S110 - already failed; free what can be freed
                        pass
        return self._result(names, data, inst)

    # --- the steps ---------------------------------------------------------------------

    def _prepare(self, inst: Mapping[str, _Instance], names: list[str]) -> None:
        """Per unit: its inputs (links and externals) in as few arrays as possible, one
        per type (a new one where a later link sets an input again), each set with one
        call; a link is read straight into its slice of the array."""
        segments: dict[str, list[tuple]] = {u.name: [] for u in self.units}
        for link in self.links:
            src = inst[link.src]
            for tr in _transfers(src.unit.fmu, inst[link.dst].unit.fmu, link.names):
                segments[link.dst].append((link.src, tr.type, list(tr.src), list(tr.dst)))
        for k, e in enumerate(self.externals):
            vrs = [inst[e.unit].unit.fmu.variables[x].valueReference for x in e.inputs]
            segments[e.unit].append((k, "Real", None, vrs))
        for name, segs in segments.items():
            i = inst[name]
            groups: list[dict] = []
            for seg in segs:
                type_, dst = seg[1], seg[3]
                g = groups[-1] if groups else None
                if g is None or g["type"] != type_ or g["set"] & set(dst):
                    g = {"type": type_, "vrs": [], "set": set(), "segs": []}
                    groups.append(g)
                g["segs"].append((seg, len(g["vrs"])))
                g["vrs"] += dst
                g["set"] |= set(dst)
            for g in groups:
                type_, n_all = g["type"], len(g["vrs"])
                ct, setter = _CTYPES[type_], i.set[type_]
                buf = (ct * n_all)()
                i.buffers.append(buf)
                i.writes.append((setter, i.comp, (ctypes.c_uint * n_all)(*g["vrs"]), n_all, buf))
                view = np.ctypeslib.as_array(buf) if type_ == "Real" else None
                for (source, _, src_vrs, dst), off in g["segs"]:
                    n = len(dst)
                    ptr = ctypes.cast(ctypes.byref(buf, off * ctypes.sizeof(ct)), ctypes.POINTER(ct))
                    dst_vrs = (ctypes.c_uint * n)(*dst)
                    if isinstance(source, str):
                        s = inst[source]
                        check = view[off : off + n] if source in self.finite_sources and view is not None else None
                        read = (source, s.get[type_], s.comp, (ctypes.c_uint * n)(*src_vrs), n, ptr, check)
                        i.reads.append(read)
                        i.inits.append((read, None, buf, off, setter, dst_vrs))
                    else:
                        i.ext.append((source, buf, off, n))
                        i.inits.append((None, source, buf, off, setter, dst_vrs))
        col = {name: c for c, name in enumerate(names)}
        for u in self.units:
            i = inst[u.name]
            by_vr = {u.fmu.variables[x].valueReference: x for x in u.record}
            for tr in _transfers(u.fmu, u.fmu, list(u.record)):
                cols = [col[u.signal(by_vr[vr])] for vr in tr.src]
                contiguous = cols == list(range(cols[0], cols[0] + len(cols)))
                where = slice(cols[0], cols[0] + len(cols)) if contiguous else np.array(cols, dtype=np.intp)
                i.records.append((i.get[tr.type], i.comp, tr.src, tr.n, tr.buf, tr.view, where))

    def _initialise(self, inst: Mapping[str, _Instance]) -> None:
        for name in self.init_order:
            s = inst[name].slave
            s.setupExperiment(startTime=0.0)
            s.enterInitializationMode()
        values = [tuple(e.function(0.0)) for e in self.externals]
        done: set[str] = set()
        for name in self.init_order:
            i = inst[name]
            i.unit.fmu.set(i.slave, i.unit.params)
            # Links from the units already initialised, then the external inputs at 0.
            for read, _, _, _, setter, dst_vrs in i.inits:
                if read is not None and read[0] in done:
                    _, get, comp, src_vrs, n, ptr, _ = read
                    get(comp, src_vrs, n, ptr)
                    setter(i.comp, dst_vrs, n, ptr)
            for read, k, buf, off, setter, dst_vrs in i.inits:
                if read is None:
                    n = len(values[k])
                    buf[off : off + n] = values[k]
                    setter(i.comp, dst_vrs, n, ctypes.cast(ctypes.byref(buf, off * 8), ctypes.POINTER(ctypes.c_double)))
            i.slave.exitInitializationMode()
            done.add(name)

    @staticmethod
    def _read_links(i: _Instance, t: float) -> None:
        for src, get, comp, vrs, n, ptr, check in i.reads:
            get(comp, vrs, n, ptr)
            if check is not None and not np.isfinite(check).all():
                raise NonFinite(f"non-finite {src} output at t = {t:.2f} s")

    @staticmethod
    def _write_inputs(i: _Instance, values: Sequence[tuple]) -> None:
        """The external inputs of `values` into their slices, then every input array."""
        for k, buf, off, n in i.ext:
            buf[off : off + n] = values[k]
        for set_, comp, vrs, n, buf in i.writes:
            set_(comp, vrs, n, buf)

    def _communication_point(self, inst, k, t, h, hs, m, n, data, monitor) -> None:
        functions = self._functions
        values = [tuple(f(t)) for f in functions]
        order = self._order
        jacobi = self._jacobi
        if jacobi:
            for i in order:
                self._read_links(i, t)
        for i in order:
            if not jacobi:
                self._read_links(i, t)
            self._write_inputs(i, values)
            if i.unit.sampler:
                i.step(t, hs if i.unit.minor else h)
        row = data[k]
        row[0] = t
        for i in self._recorded:
            for get, comp, vrs, nv, buf, view, where in i.records:
                get(comp, vrs, nv, buf)
                row[where] = view if view is not None else list(buf)
        for where, v in zip(self._ext_cols, values, strict=True):
            row[where] = v
        if monitor is not None:
            monitor(k, t, row)
        if k >= n:
            return
        for i in order:
            if not i.unit.sampler and not i.unit.minor:
                i.step(t, h)
        for j in range(m):
            tj = t + j * hs
            if j > 0:
                values = [tuple(f(tj)) for f in functions]
            for i in self._minor:
                if j > 0:
                    if i.unit.sampler:
                        self._read_links(i, tj)
                    self._write_inputs(i, values)
                if not i.unit.sampler or j > 0:
                    i.step(tj, hs)

    def _result(self, names: list[str], data: np.ndarray, inst: Mapping[str, _Instance]) -> RunResult:
        units = self.units_of_signals()
        signals = {name: data[:, c].copy() for c, name in enumerate(names)}
        wall_of = {name: i.wall for name, i in inst.items()}
        plant = self.by_name.get("plant")
        controller = self.by_name.get("controller")
        return RunResult(
            signals=signals,
            units=units,
            plant=plant.fmu.identifier if plant else "",
            controller=controller.fmu.identifier if controller else "",
            ordering=self.ordering,
            wall_time_controller=wall_of.get("controller", 0.0),
            wall_time_plant=wall_of.get("plant", 0.0),
            steps=len(data),
        )


def default_step(controller: Fmu, params: Mapping[str, float], step_size: float | None) -> float:
    """The communication step: given, else the controller's `sample_time` parameter as
    set, else its default experiment's step."""
    return float(step_size or params.get("sample_time") or controller.md.defaultExperiment.stepSize)


def default_stop(controller: Fmu, stop_time: float | None) -> float:
    return float(stop_time if stop_time is not None else controller.md.defaultExperiment.stopTime)


class Loop:
    """A configuration of `System` around one controller: what `ClosedLoop` and `AvionicsLoop`
    share. A subclass sets `controller`, `controller_params` and `callbacks`, builds its
    system in `system_for` and may post-process the record in `finish`."""

    controller: Fmu
    controller_params: Mapping[str, float]
    callbacks: object = None
    #: Communication step of the minor units (s); None: the controller's step.
    minor_step: float | None = None

    def system_for(self, h: float, wind: TimeFunction | None, ref_offset: TimeFunction | None) -> System:
        """The system flown at the controller step `h` with these external functions."""
        raise NotImplementedError

    def finish(self, result: RunResult) -> RunResult:
        """The record as returned (also a failed run's `partial_result`)."""
        return result

    def run(
        self,
        stop_time: float | None = None,
        step_size: float | None = None,
        wind: TimeFunction | None = None,
        ref_offset: TimeFunction | None = None,
        progress: bool = False,
        description: str = "",
    ) -> RunResult:
        """Fly from 0 to `stop_time` (default: the controller's default experiment) at the
        controller step `step_size` (default: its `sample_time`); `wind` and `ref_offset` are
        functions of time giving (n, e, d)."""
        h = default_step(self.controller, self.controller_params, step_size)
        system = self.system_for(h, wind, ref_offset)
        try:
            result = system.run(
                default_stop(self.controller, stop_time),
                h,
                minor_step=self.minor_step,
                callbacks=self.callbacks,
                progress=progress,
                description=description or self.controller.identifier,
            )
        except Exception as exc:
            partial = getattr(exc, "partial_result", None)
            if partial is not None:
                exc.partial_result = self.finish(partial)
            raise
        return self.finish(result)


__all__ = [
    "External",
    "Link",
    "Loop",
    "NonFinite",
    "ORDERINGS",
    "System",
    "Unit",
    "check_ordering",
    "default_step",
    "default_stop",
    "wire",
]
