//! `tailsitter_px4`: PX4-Autopilot's tail-sitter VTOL control path
//! ([`px4_control::Px4Controller`]) bound to the generic FMI 2.0 Co-Simulation export layer
//! through the one adapter of every co-simulation unit ([`controller_fmu::UnitFmu`]).
//! Only the parameters live here; the variables are declared in
//! `modelDescription/tailsitter_px4.json`, the ports in its controller-interface
//! fragment, and timing, state and messages in `controller-fmu` (docs/DESIGN.md §2).

use px4_control::{Px4Config, Px4Controller};

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

// The design model (parameter group `design_airframe`, default = the plant's nominal
// airframe) gives the effectiveness, the trims and the derived parameters.
controller_fmu::flight_controller_binding!(Px4, Px4Controller, "PX4", |vars| Px4Config {
    airframe: vars.design_airframe(),
    mission: vars.mission(),
    params: vars.px4(),
});

/// One controller instance.
pub type Px4Model = controller_fmu::UnitFmu<Px4>;

fmi2_export::export_fmu!(Px4Model);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(Px4Model);

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_export::VariableStore;

    #[test]
    fn initialization_commands_the_climb_and_steps_hold_between_samples() {
        controller_fmu::testing::assert_sampled_between_steps::<Px4Model>(
            Variables::with_start_values(),
            // Start values are the trimmed climb: the hover thrust is derived from that trim,
            // so the first command is close to its thrust.
            |v| {
                assert!(
                    (v.thrust_cmd - v.thrust).abs() < 0.5,
                    "{} vs {}",
                    v.thrust_cmd,
                    v.thrust
                );
                assert_eq!(v.phase, 0);
            },
            // The D term of the velocity loop and the integrators see a vertical speed.
            |v| {
                v.accel_x = 12.0;
                v.vel_d = 1.0;
            },
            |v| v.thrust_cmd,
            (|v: &mut Variables| v.q = f64::NAN, "q"),
        );
    }

    #[test]
    fn invalid_parameter_is_an_error_naming_it() {
        let mut vars = Variables::with_start_values();
        vars.MC_ROLL_P = f64::NAN;
        controller_fmu::testing::assert_initialize_refuses::<Px4Model>(vars, "MC_ROLL_P");
        let mut vars = Variables::with_start_values();
        vars.mass = 0.0;
        controller_fmu::testing::assert_initialize_refuses::<Px4Model>(vars, "mass");
    }

    #[test]
    fn parameter_start_values_are_the_crate_defaults() {
        assert_eq!(Variables::with_start_values().px4(), px4_control::Px4Params::default());
        assert_eq!(
            Variables::with_start_values().design_airframe(),
            tailsitter_physics::Airframe::default()
        );
    }

    #[test]
    fn state_round_trip() {
        controller_fmu::testing::assert_state_round_trip::<Px4Model>(
            Variables::with_start_values(),
            |v| v.accel_x = 11.0,
            |v| vec![v.thrust_cmd, v.elevator_cmd],
        );
    }
}
