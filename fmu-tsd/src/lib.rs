//! `tailsitter_tsd`: the time-scale-decoupled controller of thesis chapter 4
//! ([`tsd_control::TsdController`]) bound to the generic FMI 2.0 Co-Simulation export
//! layer through the one adapter of every co-simulation unit ([`controller_fmu::UnitFmu`]).
//! Only the parameters live here; the variables are declared in
//! `modelDescription/tailsitter_tsd.json`, the ports in its controller-interface
//! fragment, and timing, state and messages in `controller-fmu` (docs/DESIGN.md §2).

use tsd_control::{TsdConfig, TsdController};

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

// The design model (parameter group `design_airframe`, default = the plant's nominal
// airframe) is the controller's model of the aircraft; it may differ from the plant's.
controller_fmu::flight_controller_binding!(Tsd, TsdController, "TSD", |vars| TsdConfig {
    airframe: vars.design_airframe(),
    mission: vars.mission(),
    params: vars.tsd(),
});

/// One controller instance.
pub type TsdModel = controller_fmu::UnitFmu<Tsd>;

fmi2_export::export_fmu!(TsdModel);
// The same model as an FMI 3.0 FMU (fmi3* symbols; dist/fmi3/<id>.fmu).
fmi3_export::export_fmu3!(TsdModel);

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2_export::{FmuModel, Logger, VariableStore};

    #[test]
    fn initialization_holds_the_trim_command_and_steps_hold_between_samples() {
        controller_fmu::testing::assert_sampled_between_steps::<TsdModel>(
            Variables::with_start_values(),
            // Start values are the trimmed climb: the first command is the measured trim.
            |v| {
                assert!((v.thrust_cmd - v.thrust).abs() < 1e-9, "{}", v.thrust_cmd);
                assert_eq!(v.phase, 0);
            },
            |v| v.accel_x = 12.0,
            |v| v.thrust_cmd,
            (|v: &mut Variables| v.q = f64::NAN, "q"),
        );
    }

    #[test]
    fn invalid_parameter_is_an_error_naming_it() {
        let mut vars = Variables::with_start_values();
        vars.t_level = f64::NAN;
        controller_fmu::testing::assert_initialize_refuses::<TsdModel>(vars, "t_level");
    }

    #[test]
    fn design_model_start_values_are_the_plant_defaults() {
        assert_eq!(
            Variables::with_start_values().design_airframe(),
            tailsitter_physics::Airframe::default()
        );
    }

    #[test]
    fn invalid_design_parameter_is_an_error_naming_it() {
        let mut vars = Variables::with_start_values();
        vars.mass = 0.0;
        controller_fmu::testing::assert_initialize_refuses::<TsdModel>(vars, "mass");
    }

    fn commands(v: &Variables) -> tailsitter_physics::InputVector {
        tailsitter_physics::InputVector::from([
            v.thrust_cmd,
            v.elevator_cmd,
            v.aileron_cmd,
            v.rudder_cmd,
            v.flap_collective_cmd,
            v.flap_differential_cmd,
            v.vertical_flap_cmd,
        ])
    }

    /// Fly 15 s of the default mission through the binding with the nominal plant and
    /// the design C_m_alpha scaled by `scale`; the final plant state.
    fn fly_design(scale: f64) -> tailsitter_physics::StateVector {
        use tailsitter_physics::{Airframe, Plant};
        let plant = Plant::new(Airframe::default());
        let mut x = plant.trim_vertical_climb(3.0).unwrap().state;
        let mut vars = Variables::with_start_values();
        vars.c_m_alpha_a0 *= scale;
        vars.c_m_alpha_a1 *= scale;
        let mut model = TsdModel::new(&vars);
        let mut log = Logger::null();
        let zero = nalgebra::Vector3::zeros();
        let u = commands(&vars);
        vars.set_measurement(&flight_mission::measure(&plant, &x, &u, &zero));
        model.initialize(&mut vars, 0.0, &mut log).unwrap();
        let h = 0.02;
        for k in 0..750 {
            let u = commands(&vars);
            vars.set_measurement(&flight_mission::measure(&plant, &x, &u, &zero));
            model.do_step(&mut vars, k as f64 * h, h, &mut log).unwrap();
            plant.advance(&mut x, &commands(&vars), &zero, h).unwrap();
        }
        x
    }

    #[test]
    fn design_c_m_alpha_changes_the_flight() {
        // Design C_m_alpha x 1.2 (the thesis's §5 mismatch), plant nominal: through the
        // transition (5-10 s) the moment feed-forward differs, so the flights part by far
        // more than round-off (1 mm in position at 15 s).
        let (xn, xp) = (fly_design(1.0), fly_design(1.2));
        let dp = (xp.fixed_rows::<3>(0) - xn.fixed_rows::<3>(0)).norm();
        assert!(dp > 1e-3, "position difference {dp} m at 15 s");
    }

    #[test]
    fn state_round_trip() {
        controller_fmu::testing::assert_state_round_trip::<TsdModel>(
            Variables::with_start_values(),
            |v| v.accel_x = 11.0,
            |v| vec![v.thrust_cmd, v.elevator_cmd],
        );
    }
}
