//! Scan one tuning parameter over values and print the mission metrics (tuning aid).
//!
//! `cargo run --release -p missions --example tsd_scan -- <param> <v1> <v2> ...`
//!
//! With `TSD_SCAN_WIND=1` it also hovers 35 s (vertical flight) in a constant 5 m/s wind
//! from N, E, S, W, NE and flies the default mission in a 3 m/s crosswind (from the east),
//! printing max / final position error (m).

use closed_loop::{fly, MissionCheck, Ordering, Scenario, Wind};
use flight_mission::MissionParams;
use nalgebra::Vector3;
use tailsitter_physics::{Airframe, Plant};
use tsd_control::{TsdController, TsdParams};

fn set(p: &mut TsdParams, name: &str, value: f64) {
    let mut found = false;
    macro_rules! fields {
        ($($f:ident),*) => { $( if name == stringify!($f) { p.$f = value; found = true; } )* };
    }
    fields!(
        axial_pole_1_vertical,
        axial_pole_2_vertical,
        axial_pole_1_level,
        axial_pole_2_level,
        roll_pole_re_vertical,
        roll_pole_im_vertical,
        roll_pole_re_level,
        roll_pole_im_level,
        normal_pole_real_vertical,
        normal_pole_re_vertical,
        normal_pole_im_vertical,
        normal_pole_real_level,
        normal_pole_re_level,
        normal_pole_im_level,
        directional_pole_real_vertical,
        directional_pole_re_vertical,
        directional_pole_im_vertical,
        directional_pole_real_level,
        directional_pole_re_level,
        directional_pole_im_level,
        nvd_pole_vertical,
        nvd_pole_level,
        guidance_pole_re_vertical,
        guidance_pole_im_vertical,
        guidance_pole_re_level,
        guidance_pole_im_level,
        antiwindup_gain,
        flap_mixing_factor,
        vertical_flap_mixing_factor,
        min_airspeed,
        normal_vector_blend_time,
        min_normal_accel,
        wind_frame_speed_low,
        wind_frame_speed_high,
        feedforward_lead
    );
    assert!(found, "unknown parameter {name}");
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = &args[1];
    let plant = Plant::new(Airframe::default());
    let theta_trim = plant.trim_level(25.0).unwrap().theta;
    for v in &args[2..] {
        let value: f64 = v.parse().unwrap();
        let mut p = TsdParams::default();
        set(&mut p, name, value);
        let mut line = format!("{name} = {value:8.3}:");
        for (label, t1, t2, ordering) in [
            ("default", 5.0, 10.0, Ordering::GaussSeidel),
            ("jacobi", 5.0, 10.0, Ordering::Jacobi),
            ("fast", 3.0, 4.0, Ordering::GaussSeidel),
        ] {
            let mission = MissionParams {
                t_transition_1: t1,
                t_transition_2: t2,
                ..Default::default()
            };
            let x0 = plant.trim_vertical_climb(3.0).unwrap().state;
            let mut ctl = TsdController::new(Airframe::default(), mission, p).unwrap();
            let mut sc = Scenario::mission(mission);
            sc.ordering = ordering;
            let tr = fly(&plant, x0, &mut ctl, &sc);
            let check = MissionCheck::of(&tr, &mission, theta_trim);
            line += &format!(
                "  {label}: {} max {:.2} m, α {:.1}°, pitch {:.1}°",
                if check.passed() && tr.completed() { "ok" } else { "FAIL" },
                tr.max_pos_error(),
                tr.max_alpha(0.0, 100.0).to_degrees(),
                check.level_pitch_error.to_degrees()
            );
        }
        println!("{line}");
        if std::env::var("TSD_SCAN_WIND").is_ok() {
            println!("    {}", wind_line(&plant, p, theta_trim));
        }
    }
}

/// Hover in a steady 5 m/s wind from five directions, then the default mission in a 3 m/s crosswind.
fn wind_line(plant: &Plant, p: TsdParams, theta_trim: f64) -> String {
    let mut line = String::from("wind 5 m/s, max/final:");
    let s = std::f64::consts::FRAC_1_SQRT_2;
    // Wind vectors (NED, air velocity): a wind *from* the north blows south.
    for (label, w) in [
        ("N", [-1.0, 0.0]),
        ("E", [0.0, -1.0]),
        ("S", [1.0, 0.0]),
        ("W", [0.0, 1.0]),
        ("NE", [-s, -s]),
    ] {
        let mission = MissionParams {
            t_vertical_1: 40.0,
            ..Default::default()
        };
        let x0 = plant.trim_vertical_climb(3.0).unwrap().state;
        let mut ctl = TsdController::new(Airframe::default(), mission, p).unwrap();
        let mut sc = Scenario::mission(mission);
        sc.stop_time = 35.0;
        sc.wind = Wind::Constant(Vector3::new(5.0 * w[0], 5.0 * w[1], 0.0));
        let tr = fly(plant, x0, &mut ctl, &sc);
        let fin = tr.window(15.0, 36.0).map(|s| s.pos_error()).fold(0.0, f64::max);
        line += &format!(
            "  {label}: {:.2}/{:.2}{}",
            tr.max_pos_error(),
            fin,
            if tr.completed() { "" } else { " FAIL" }
        );
    }
    let mission = MissionParams::default();
    let x0 = plant.trim_vertical_climb(3.0).unwrap().state;
    let mut ctl = TsdController::new(Airframe::default(), mission, p).unwrap();
    let mut sc = Scenario::mission(mission);
    sc.wind = Wind::Constant(Vector3::new(0.0, -3.0, 0.0));
    let tr = fly(plant, x0, &mut ctl, &sc);
    let check = MissionCheck::of(&tr, &mission, theta_trim);
    line += &format!(
        "  | mission 3 m/s crosswind: {} max {:.2} m, α {:.1}°",
        if check.passed() && tr.completed() { "ok" } else { "FAIL" },
        tr.max_pos_error(),
        tr.max_alpha(0.0, 100.0).to_degrees()
    );
    line
}
