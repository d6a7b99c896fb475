//! Issue 16, front transition: the profile's flight-path angle γ_ref(t) against the flown γ(t)
//! of the tuned LQR (Gauss-Seidel) and TSD (Gauss-Seidel, Jacobi), with the rotation figures
//! of `envelope_transitions` for both controllers and masters (tsd-control README, "Front
//! transition: preview in path axes").
//! `cargo run --release -p analysis --example front_probe [t1 t2]` (default: the fast mission).
use analysis::controllers::Kind;
use analysis::envelope_transitions::{fly_mission, measure, ROTATION_TOLERANCE};
use closed_loop::{Ordering, Sample, Trace};
use flight_mission::MissionParams;
use guidance::{PointMass, Profile, ProfileLimits};
use tailsitter_physics::Airframe;

fn gamma_deg(s: &Sample) -> f64 {
    let v = s.measurement.vel_ned;
    (-v.z).atan2(v.x.hypot(v.y)).to_degrees()
}

fn main() {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().expect("t1 t2 (s)"))
        .collect();
    let f = MissionParams::fast_limited();
    let (t1, t2) = if a.len() >= 2 {
        (a[0], a[1])
    } else {
        (f.t_transition_1, f.t_transition_2)
    };
    let m = MissionParams {
        t_transition_1: t1,
        t_transition_2: t2,
        ..MissionParams::default()
    };
    let pm = PointMass::from_level_trim(&Airframe::default(), m.v_level).expect("level trim");
    let p = Profile::new(&m, &pm, &ProfileLimits::of(&m)).expect("profile");
    let s = m.phase_starts();
    println!(
        "profile: front rotation {:?} s (5°)",
        p.settle_time(s[1], s[3], 0.0, ROTATION_TOLERANCE)
    );
    let mut traces: Vec<Trace> = Vec::new();
    for kind in Kind::ALL {
        for ord in [Ordering::GaussSeidel, Ordering::Jacobi] {
            let tr = fly_mission(kind, 0, ord, t1, t2).expect("flight");
            let r = measure(&tr, t1, t2);
            println!(
                "{} {ord:?}: rotation {:.2}/{:.2} s, α {:.1}°, altitude dev. {:.2}/{:.2} m, max error {:.2} m",
                kind.name(),
                r.rotation_t1,
                r.rotation_t2,
                r.max_alpha_deg,
                r.alt_dev_t1,
                r.alt_dev_t2,
                r.max_pos_error
            );
            traces.push(tr);
        }
    }
    println!("  t−T1 | γ_ref α_ref V_ref | LQR GS: γ α θ V Δh | TSD GS: γ α θ V Δh | TSD Jacobi: γ α θ V Δh");
    let row = |tr: &Trace, t: f64| {
        let x = tr.samples.iter().find(|x| x.t >= t - 1e-9).expect("sample");
        format!(
            "{:6.1} {:5.1} {:6.1} {:5.1} {:5.2}",
            gamma_deg(x),
            x.measurement.alpha.to_degrees(),
            x.theta.to_degrees(),
            x.measurement.airspeed,
            -(x.measurement.pos_ned.z - x.diagnostics.ref_pos_ned.z)
        )
    };
    let mut k = -2;
    while f64::from(k) * 0.1 < t1 + 1.5 {
        let t = s[1] + f64::from(k) * 0.1;
        let pp = p.at(t);
        println!(
            "{:6.2} | {:6.1} {:5.1} {:5.1} | {} | {} | {}",
            t - s[1],
            pp.gamma.to_degrees(),
            pp.alpha.to_degrees(),
            pp.v,
            row(&traces[0], t),
            row(&traces[2], t),
            row(&traces[3], t)
        );
        k += 1;
    }
}
