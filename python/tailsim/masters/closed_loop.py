"""Plant + controller: the reference configuration of `tailsim.masters.system`.

Gauss-Seidel (the reference): at each communication point t the controller inputs
are set from the plant outputs at t, the controller steps, the plant inputs are set
from the controller outputs, the plant steps. Jacobi: both units are set from values
at t before either steps, so the plant flies the command of the previous sample.

With `atmosphere` (the `tailsitter_atmosphere` FMU) the wind is a third unit instead of a
function of time: plant `pos_n/e/d`, `airspeed` → atmosphere, atmosphere `wind_n/e/d` →
plant, wired by name. It is a sampler stepped between the controller and the plant: in
Gauss-Seidel it reads the plant outputs at t (computed with the wind the plant holds from
its last step), steps (t, h) and the plant flies its output over [t, t + h); in Jacobi the
plant flies its output of the previous point (one step of delay). It leaves
initialisation after the plant (its start from the plant's initial outputs, the plant's
wind inputs at their start value 0). The native loop mirrors this
(`closed_loop::wind_source`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from .fmu import Fmu
from .profiles import TimeFunction, zero
from .system import External, Link, Loop, System, Unit, check_ordering, wire

#: The plant's wind inputs and the controller's reference-offset inputs (NED).
WIND = ("wind_n", "wind_e", "wind_d")
REF_OFFSET = ("ref_offset_n", "ref_offset_e", "ref_offset_d")


def wind_external(function: TimeFunction | None) -> External:
    return External("plant", WIND, function or zero, WIND, "m/s")


def ref_offset_external(function: TimeFunction | None) -> External:
    return External("controller", REF_OFFSET, function or zero, REF_OFFSET, "m")


def commands_driven(plant: Fmu, controller: Fmu) -> list[str]:
    """The controller outputs wired to plant inputs; every plant command input must be one."""
    to_plant = wire(controller, plant)
    missing = [n for n in plant.names("input") if n.endswith("_cmd") and n not in to_plant]
    if missing:
        raise ValueError(f"{controller.identifier} does not drive plant inputs {missing}")
    return to_plant


def real_outputs(fmu: Fmu) -> list[str]:
    return [n for n in fmu.names("output") if fmu.variables[n].type == "Real"]


def int_outputs(fmu: Fmu) -> list[str]:
    return [n for n in fmu.names("output") if fmu.variables[n].type == "Integer"]


class ClosedLoop(Loop):
    """Plant + controller, wired by port name.

    plant_params / controller_params: start values set in initialisation mode
    (parameters and inputs, by name). `wind` and `ref_offset` are functions of
    time giving (n, e, d); they drive the plant's `wind_*` and the controller's
    `ref_offset_*` inputs. `atmosphere`: the atmosphere FMU as the wind source instead,
    with `atmosphere_params` (by name; its defaults are calm); its outputs are recorded as
    `wind_n/e/d`.
    """

    def __init__(
        self,
        plant: Fmu,
        controller: Fmu,
        plant_params: Mapping[str, float] | None = None,
        controller_params: Mapping[str, float] | None = None,
        ordering: str = "gauss-seidel",
        callbacks=None,
        atmosphere: Fmu | None = None,
        atmosphere_params: Mapping[str, float] | None = None,
    ):
        check_ordering(ordering)
        self.plant, self.controller = plant, controller
        self.atmosphere = atmosphere
        self.atmosphere_params = dict(atmosphere_params or {})
        if atmosphere is None and self.atmosphere_params:
            raise ValueError("atmosphere_params without an atmosphere FMU")
        self.plant_params = dict(plant_params or {})
        self.controller_params = dict(controller_params or {})
        self.ordering = ordering
        self.callbacks = callbacks
        # Wiring by name: controller input ← plant output, controller output → plant input.
        self.to_controller = wire(plant, controller)
        self.to_plant = commands_driven(plant, controller)
        if atmosphere is not None:
            self.to_atmosphere = wire(plant, atmosphere)
            undriven = [n for n in atmosphere.names("input") if n not in self.to_atmosphere]
            self.wind_to_plant = wire(atmosphere, plant)
            if undriven or sorted(self.wind_to_plant) != sorted(WIND):
                raise ValueError(
                    f"{atmosphere.identifier} must read plant outputs only and drive the plant's {list(WIND)}"
                )

    def system(
        self,
        wind: TimeFunction | None = None,
        ref_offset: TimeFunction | None = None,
        record_plant: Sequence[str] | None = None,
        record_controller: Sequence[str] | None = None,
        finite_sources: Sequence[str] = (),
    ) -> System:
        """The system of this loop; records every plant output and the controller's Real
        then Integer outputs unless `record_*` name others."""
        c = self.controller
        controller = Unit(
            "controller",
            c,
            self.controller_params,
            sampler=True,
            record=list(record_controller if record_controller is not None else real_outputs(c) + int_outputs(c)),
        )
        plant = Unit(
            "plant",
            self.plant,
            self.plant_params,
            minor=True,
            record=list(record_plant if record_plant is not None else self.plant.names("output")),
        )
        links = [Link("plant", "controller", self.to_controller), Link("controller", "plant", self.to_plant)]
        if self.atmosphere is None:
            return System(
                [controller, plant],
                links,
                [wind_external(wind), ref_offset_external(ref_offset)],
                ordering=self.ordering,
                init_order=["plant", "controller"],
                finite_sources=finite_sources,
                record_order=["plant", "controller"],
            )
        if wind is not None:
            raise ValueError("a wind function and an atmosphere FMU: give one wind source")
        atmosphere = Unit("atmosphere", self.atmosphere, self.atmosphere_params, sampler=True, record=list(WIND))
        return System(
            [controller, atmosphere, plant],
            [
                *links,
                Link("plant", "atmosphere", self.to_atmosphere),
                Link("atmosphere", "plant", self.wind_to_plant),
            ],
            [ref_offset_external(ref_offset)],
            ordering=self.ordering,
            init_order=["plant", "controller", "atmosphere"],
            finite_sources=finite_sources,
            record_order=["plant", "controller", "atmosphere"],
        )

    def system_for(self, h: float, wind: TimeFunction | None, ref_offset: TimeFunction | None) -> System:
        return self.system(wind, ref_offset)


__all__ = ["REF_OFFSET", "WIND", "ClosedLoop", "commands_driven", "ref_offset_external", "wind_external"]
