//! One TSD job of the native campaign (`analysis campaign-jobs` JSON, one object) flown and
//! printed every 0.5 s: position error, air angles, pitch, airspeed, thrust, rudder and vertical
//! flaps (used to read the runs a change gains or loses; tsd-control README).
//! `cargo run --release -p analysis --example job_trace -- job.json`
use analysis::native_campaign::{mission_of, plant_of, wind_of, Job};
use closed_loop::{fly, MeasuredWind, Scenario};
use tailsitter_physics::Airframe;
use tsd_control::{TsdController, TsdParams};

fn main() {
    let path = std::env::args().nth(1).expect("job JSON file");
    let job: Job = serde_json::from_str(&std::fs::read_to_string(path).expect("readable job file")).expect("a job");
    let (plant, x0) = plant_of(&job).expect("plant");
    let mission = mission_of(&job).expect("mission");
    let mut sc = Scenario::mission(mission);
    sc.stop_time = job.stop_time;
    sc.comm_step = job.step_size;
    sc.wind = wind_of(&job, plant.ground.height);
    sc.measured_wind = MeasuredWind::HeldInput;
    let params = TsdParams {
        configuration: job.configuration,
        ..TsdParams::default()
    };
    let mut c = TsdController::new(Airframe::default(), mission, params).expect("controller");
    let tr = fly(&plant, x0, &mut c, &sc);
    for s in tr.samples.iter().step_by(25) {
        let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
        println!(
            "{:6.2} ph {} err {:7.2} {:7.2} {:7.2} |{:6.2}| α {:6.1} β {:6.1} θ {:6.1} V {:5.1} T {:5.1} δr {:6.1} δv {:6.1}",
            s.t,
            s.diagnostics.phase as i32,
            e.x,
            e.y,
            e.z,
            e.norm(),
            s.measurement.alpha.to_degrees(),
            s.measurement.beta.to_degrees(),
            s.theta.to_degrees(),
            s.measurement.airspeed,
            s.command.thrust,
            s.command.rudder.to_degrees(),
            s.command.vertical_flap.to_degrees()
        );
    }
    if let Some(f) = tr.failure {
        println!("{f}");
    }
}
