"""The trims docs/DESIGN.md and docs/TRANSITION.md quote (registered into
`tailsim.reports.docs.BLOCKS`).

Source: `docs/design_trims.json`, written by
`cargo run --release -p analysis --example design_trims -- docs/design_trims.json`: the
plant's level trim at V_L and vertical-climb trim at V_V on the thesis's and the global
aerodynamic model, and the point-mass model's climb thrust T_climb = m g + D.
"""

from __future__ import annotations

from .docs import Sources, block

TRIMS = "design_trims.json"


def _minus(text: str) -> str:
    return text.replace("-", "−")


@block("design.level_trim", TRIMS)
def _level_trim(src: Sources) -> str:
    t = src.json(TRIMS)
    lv = t["plant"]["thesis"]["level"]
    return _minus(
        f"the level trim at {t['v_level']:g} m/s needs C_L = {lv['c_l_needed']:.2f} (α = {lv['alpha_deg']:.1f}°, "
        f"δe = {lv['elevator_deg']:.1f}°, the elevator's own lift included)"
    )


@block("design.climb_trim", TRIMS)
def _climb_trim(src: Sources) -> str:
    t = src.json(TRIMS)
    cl = t["plant"]["thesis"]["climb"]
    weight = t["mass"] * t["gravity"]
    return (
        f"the {t['v_vertical']:g} m/s climb needs T = {cl['thrust']:.1f} N (m g = {weight:.1f} N) "
        f"with w = {cl['induced_velocity']:.1f} m/s"
    )


@block("transition.t_climb", TRIMS)
def _t_climb(src: Sources) -> str:
    return f"{src.json(TRIMS)['point_mass_t_climb']:.1f} N"


@block("physics.trims", TRIMS)
def _physics_trims(src: Sources) -> str:
    """crates/tailsitter-physics/README.md: the level and climb trims of the default airframe."""
    t = src.json(TRIMS)
    lv, cl = t["plant"]["thesis"]["level"], t["plant"]["thesis"]["climb"]
    return "| condition | result |\n|---|---|\n" + _minus(
        f"| level {t['v_level']:g} m/s | α = θ = {lv['alpha_deg']:.3f}°, δe = {lv['elevator_deg']:.3f}°, "
        f"T = {lv['thrust']:.3f} N, w = {lv['induced_velocity']:.3f} m/s |\n"
        f"| vertical climb {t['v_vertical']:g} m/s | T = {cl['thrust']:.3f} N (= m g + q̄S C_D0), "
        f"w = {cl['induced_velocity']:.3f} m/s, δe = {abs(cl['elevator_deg']):.0f}, θ = {cl['theta_deg']:.0f}° |"
    )
