//! The closed-loop master's timing and wiring, with scripted controllers.

use closed_loop::{fly, Ordering, Scenario, Wind};
use flight_mission::{
    Command, ControlError, ControllerInput, ControllerOutput, Diagnostics, MissionParams, ParamError, Phase,
    SampledUnit,
};
use nalgebra::Vector3;
use tailsitter_physics::{idx, Airframe, Plant};

/// Holds a fixed command; the reference is wherever the aircraft is plus the offset.
#[derive(Clone, PartialEq)]
struct Hold {
    command: Command,
    samples: Vec<f64>,
}

impl SampledUnit for Hold {
    type Config = Hold;
    type Input = ControllerInput;
    type Output = ControllerOutput;

    fn build(config: &Hold) -> Result<Self, ParamError> {
        Ok(config.clone())
    }

    fn sample_time(_: &Hold) -> f64 {
        0.02
    }

    fn save(&self, _: &mut impl FnMut(f64)) {}

    fn restore(&mut self, _: &mut impl FnMut() -> Option<f64>) -> Result<(), ControlError> {
        Ok(())
    }

    fn sample(&mut self, input: &ControllerInput) -> Result<ControllerOutput, ControlError> {
        self.samples.push(input.t);
        // A command that encodes the sample index, to observe the master's ordering.
        let mut command = self.command;
        command.aileron = 1e-9 * self.samples.len() as f64;
        Ok(ControllerOutput {
            command,
            diagnostics: Diagnostics {
                ref_pos_ned: input.measurement.pos_ned + input.ref_offset_ned,
                ref_airspeed: input.measurement.airspeed,
                phase: Phase::Vertical1,
                pos_error: input.ref_offset_ned.norm(),
            },
            notice: None,
        })
    }
}

fn climb() -> (Plant, tailsitter_physics::Trim, Hold) {
    let plant = Plant::new(Airframe::default());
    let trim = plant.trim_vertical_climb(3.0).unwrap();
    let u = trim.inputs;
    let command = Command {
        thrust: u[idx::THRUST_CMD],
        elevator: u[idx::ELEVATOR_CMD],
        ..Command::default()
    };
    (
        plant,
        trim,
        Hold {
            command,
            samples: Vec::new(),
        },
    )
}

#[test]
fn trimmed_climb_held_open_loop() {
    let (plant, trim, mut hold) = climb();
    let mut scenario = Scenario::mission(MissionParams::default());
    scenario.stop_time = 2.0;
    let trace = fly(&plant, trim.state, &mut hold, &scenario);
    assert!(trace.completed(), "{:?}", trace.failure);
    assert_eq!(trace.samples.len(), 101);
    let last = trace.samples.last().unwrap();
    assert!(
        (last.measurement.pos_ned.z + 6.0).abs() < 1e-3,
        "{}",
        last.measurement.pos_ned.z
    );
    assert!((last.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-3);
    // Samples at every multiple of the sample time, the first at 0.
    assert_eq!(hold.samples.len(), 101);
    assert!(hold
        .samples
        .iter()
        .enumerate()
        .all(|(k, t)| (t - 0.02 * k as f64).abs() < 1e-12));
}

#[test]
fn jacobi_flies_the_previous_command() {
    let (plant, trim, hold) = climb();
    let mut scenario = Scenario::mission(MissionParams::default());
    scenario.stop_time = 0.2;
    let gs = fly(&plant, trim.state, &mut hold.clone(), &scenario);
    scenario.ordering = Ordering::Jacobi;
    let jacobi = fly(&plant, trim.state, &mut hold.clone(), &scenario);
    for k in 1..gs.samples.len() {
        assert_eq!(
            jacobi.samples[k].command.aileron,
            gs.samples[k - 1].command.aileron,
            "step {k}"
        );
    }
    assert_eq!(jacobi.samples[0].command, gs.samples[0].command);
}

#[test]
fn comm_step_finer_than_sample_time_holds_the_command() {
    let (plant, trim, mut hold) = climb();
    let mut scenario = Scenario::mission(MissionParams::default());
    scenario.stop_time = 0.1;
    scenario.comm_step = 0.005;
    let trace = fly(&plant, trim.state, &mut hold, &scenario);
    assert_eq!(hold.samples.len(), 6, "{:?}", hold.samples);
    // Held between samples.
    assert_eq!(trace.samples[1].command, trace.samples[0].command);
    assert_ne!(trace.samples[4].command, trace.samples[3].command);
}

#[test]
fn wind_and_offsets_reach_plant_and_controller() {
    let (plant, trim, mut hold) = climb();
    let mut scenario = Scenario::mission(MissionParams::default());
    scenario.stop_time = 1.0;
    scenario.wind = Wind::Constant(Vector3::new(3.0, 0.0, 0.0));
    scenario.ref_offset_steps = vec![(0.5, Vector3::new(0.0, 5.0, 0.0))];
    let trace = fly(&plant, trim.state, &mut hold, &scenario);
    let first = &trace.samples[0];
    // A 3 m/s headwind from the north on a climbing aircraft: airspeed √(3² + 3²).
    assert!((first.measurement.airspeed - 18f64.sqrt()).abs() < 1e-9);
    assert!(trace
        .samples
        .iter()
        .all(|s| (s.pos_error() - if s.t >= 0.5 - 1e-9 { 5.0 } else { 0.0 }).abs() < 1e-9));
}

#[test]
fn plant_failure_stops_the_run_with_a_message() {
    let (plant, trim, mut hold) = climb();
    hold.command.thrust = f64::NAN;
    let scenario = Scenario::mission(MissionParams::default());
    let trace = fly(&plant, trim.state, &mut hold, &scenario);
    assert!(!trace.completed());
    assert!(
        trace.failure.as_deref().unwrap().contains("non-finite"),
        "{:?}",
        trace.failure
    );
}
