//! One TSD run of a native-campaign job file (`analysis campaign-jobs` JSON lines) flown again
//! with a trace: the job chosen by its sample id, its sampled multipliers and wind printed, the
//! largest error per phase, the flight every 0.24 s (error, wind, rates, air angles, airspeed,
//! thrust, surface commands) and, if asked, every sample to a CSV file.
//!
//! `cargo run --release -p analysis --example tsdcamp_replay -- jobs.jsonl SAMPLE_ID [TRACE.csv]`
use std::io::Write;

use analysis::native_campaign::{metrics, mission_of, plant_of, scenario_of, Job};
use closed_loop::{fly, Sample};
use tailsitter_physics::Airframe;
use tsd_control::{TsdController, TsdParams};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("jobs file (JSON lines)");
    let id: String = args.next().expect("sample id");
    let csv = args.next();
    let text = std::fs::read_to_string(&path).expect("readable jobs file");
    let job: Job = text
        .lines()
        .map(|l| serde_json::from_str::<Job>(l).expect("a job"))
        .find(|j| j.controller == "tsd" && j.key.split('/').next() == Some(id.as_str()))
        .expect("a TSD job of that sample id");
    let (plant, x0) = plant_of(&job).expect("plant");
    let mut nominal = Airframe::default();
    let nominal = nominal.named_values_mut();
    for (name, bits) in job.plant_bits.iter().filter(|(n, _)| !n.ends_with("_a1")) {
        if let Some((_, n)) = nominal.iter().find(|(n, _)| n == name) {
            print!("{name} ×{:.3}  ", f64::from_bits(*bits) / **n);
        }
    }
    println!();
    let w = job.wind;
    let f = f64::from_bits;
    println!(
        "wind n/e {:.2}/{:.2} gust n/e/d {:.2}/{:.2}/{:.2} from {:.2} s for {:.2} s, turbulence {}",
        f(w.steady_n),
        f(w.steady_e),
        f(w.gust_n),
        f(w.gust_e),
        f(w.gust_d),
        f(w.gust_start),
        f(w.gust_duration),
        w.turbulence_intensity
    );
    let mission = mission_of(&job).expect("mission");
    let sc = scenario_of(&job, &plant, mission);
    let params = TsdParams {
        configuration: job.configuration,
        ..TsdParams::default()
    };
    let mut c = TsdController::new(Airframe::default(), mission, params).expect("controller");
    let tr = fly(&plant, x0, &mut c, &sc);
    let m = metrics(&plant, &tr.samples);
    let phase_max: Vec<String> = (0..5)
        .map(|k| format!("{:.2}", m[&format!("max_err_p{k}")].unwrap_or(f64::NAN)))
        .collect();
    println!(
        "largest error {:.2} m, per phase {}",
        m["max_err"].unwrap_or(f64::NAN),
        phase_max.join(" ")
    );
    // The printout every 0.24 s: time, phase, |error| and the columns in degrees where angles.
    for s in tr.samples.iter().step_by(12) {
        let c = columns(s);
        let e = (c[2].1.powi(2) + c[3].1.powi(2) + c[4].1.powi(2)).sqrt();
        print!("{:6.2} ph {} |err| {e:5.2}", c[0].1, c[1].1);
        for (name, v) in &c[2..] {
            let v = if ANGLES.contains(name) { v.to_degrees() } else { *v };
            print!(" {name} {v:.1}");
        }
        println!();
    }
    if let Some(f) = &tr.failure {
        println!("{f}");
    }
    if let Some(path) = csv {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path).expect("writable CSV"));
        let names: Vec<&str> = columns(&tr.samples[0]).iter().map(|(n, _)| *n).collect();
        writeln!(out, "{}", names.join(",")).unwrap();
        for s in &tr.samples {
            let row: Vec<String> = columns(s).iter().map(|(_, v)| v.to_string()).collect();
            writeln!(out, "{}", row.join(",")).unwrap();
        }
    }
}

/// The columns in rad (printed in degrees, rates in deg/s).
const ANGLES: [&str; 10] = [
    "p",
    "q",
    "r",
    "alpha",
    "beta",
    "elevator",
    "aileron",
    "rudder",
    "flap_collective",
    "vertical_flap",
];

/// One sample's columns (SI units, angles in rad): time, phase, position error N/E/D, wind
/// N/E/D, body rates, α, β, airspeed and the commands.
fn columns(s: &Sample) -> [(&'static str, f64); 20] {
    let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
    let (m, c) = (&s.measurement, &s.command);
    [
        ("t", s.t),
        ("phase", f64::from(s.diagnostics.phase as i32)),
        ("err_n", e.x),
        ("err_e", e.y),
        ("err_d", e.z),
        ("wind_n", s.wind.x),
        ("wind_e", s.wind.y),
        ("wind_d", s.wind.z),
        ("p", m.rates.x),
        ("q", m.rates.y),
        ("r", m.rates.z),
        ("alpha", m.alpha),
        ("beta", m.beta),
        ("airspeed", m.airspeed),
        ("thrust", c.thrust),
        ("elevator", c.elevator),
        ("aileron", c.aileron),
        ("rudder", c.rudder),
        ("flap_collective", c.flap_collective),
        ("vertical_flap", c.vertical_flap),
    ]
}
