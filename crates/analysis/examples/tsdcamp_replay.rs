//! One TSD run of a native-campaign job file (`analysis campaign-jobs` JSON lines) flown again
//! with a trace: the job chosen by its sample id, its sampled multipliers and wind printed, the
//! largest error per phase, the flight every 0.25 s (error, air angles, pitch, airspeed, thrust,
//! rudder, vertical flaps, elevator) and, if asked, every sample to a CSV file.
//!
//! `cargo run --release -p analysis --example tsdcamp_replay -- jobs.jsonl SAMPLE_ID [TRACE.csv]`
use std::io::Write;

use analysis::native_campaign::{metrics, mission_of, plant_of, wind_of, Job};
use closed_loop::{fly, MeasuredWind, Scenario};
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
    let m = metrics(&plant, &tr.samples);
    let phase_max: Vec<String> = (0..5)
        .map(|k| format!("{:.2}", m[&format!("max_err_p{k}")].unwrap_or(f64::NAN)))
        .collect();
    println!(
        "largest error {:.2} m, per phase {}",
        m["max_err"].unwrap_or(f64::NAN),
        phase_max.join(" ")
    );
    let deg = f64::to_degrees;
    for s in tr.samples.iter().step_by(12) {
        let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
        println!(
            "{:6.2} ph {} err {:6.2} {:6.2} {:6.2} |{:5.2}| wind {:5.1} {:5.1} {:5.1} α {:6.1} β {:6.1} θ {:6.1} V {:5.1} T {:5.1} δr {:6.1} δv {:6.1} δe {:6.1} δa {:6.1}",
            s.t,
            s.diagnostics.phase as i32,
            e.x,
            e.y,
            e.z,
            e.norm(),
            s.wind.x,
            s.wind.y,
            s.wind.z,
            deg(s.measurement.alpha),
            deg(s.measurement.beta),
            deg(s.theta),
            s.measurement.airspeed,
            s.command.thrust,
            deg(s.command.rudder),
            deg(s.command.vertical_flap),
            deg(s.command.elevator),
            deg(s.command.aileron)
        );
    }
    if let Some(f) = &tr.failure {
        println!("{f}");
    }
    if let Some(path) = csv {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path).expect("writable CSV"));
        writeln!(out, "t,phase,err_n,err_e,err_d,wind_n,wind_e,wind_d,p,q,r,alpha,beta,airspeed,thrust,elevator,aileron,rudder,flap_collective,vertical_flap").unwrap();
        for s in &tr.samples {
            let e = s.measurement.pos_ned - s.diagnostics.ref_pos_ned;
            let (r, c) = (s.measurement.rates, s.command);
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                s.t,
                s.diagnostics.phase as i32,
                e.x,
                e.y,
                e.z,
                s.wind.x,
                s.wind.y,
                s.wind.z,
                r.x,
                r.y,
                r.z,
                s.measurement.alpha,
                s.measurement.beta,
                s.measurement.airspeed,
                c.thrust,
                c.elevator,
                c.aileron,
                c.rudder,
                c.flap_collective,
                c.vertical_flap
            )
            .unwrap();
        }
    }
}
