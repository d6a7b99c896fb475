//! Fly the take-off-to-landing mission once and print the figures:
//! `cargo run --release -p analysis --example takeoff_landing -- tsd [jacobi]`, or `-- report`
//! for the `takeoff_landing` value of report.json.
use analysis::controllers::Kind;
use analysis::takeoff_landing::{fly_one, mission};
use closed_loop::Ordering;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("report") {
        // The `takeoff_landing` value of report.json, both controllers, both orderings.
        let r = analysis::takeoff_landing::report(&Kind::ALL);
        println!("{}", serde_json::to_string(&r).unwrap());
        return;
    }
    let kind = if args.get(1).map(String::as_str) == Some("lqr") {
        Kind::Lqr
    } else {
        Kind::Tsd
    };
    let ordering = if args.get(2).map(String::as_str) == Some("jacobi") {
        Ordering::Jacobi
    } else {
        Ordering::GaussSeidel
    };
    let mut m = mission();
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    m.landing_target_n = env("TL_N", m.landing_target_n);
    m.landing_target_e = env("TL_E", m.landing_target_e);
    m.landing_descent_rate = env("TL_VD", m.landing_descent_rate);
    m.landing_approach_speed = env("TL_VA", m.landing_approach_speed);
    let (trace, mut f) = fly_one(kind, ordering, &m);
    let traj = std::mem::take(&mut f.trajectory);
    if std::env::var("TRACE").is_ok() {
        for r in traj.iter() {
            println!(
                "{:.1} N {:.2} E {:.2} D {:.2} | ref {:.2} {:.2} {:.2} ph {} tilt {:.1} T {:.1}",
                r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9]
            );
        }
    }
    println!("{}", serde_json::to_string_pretty(&f).unwrap());
    println!("samples {}", trace.samples.len());
}
