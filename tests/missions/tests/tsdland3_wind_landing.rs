//! The tuned TSD's take-off-to-landing mission (`analysis::takeoff_landing::mission`), cells
//! of the wind envelope (`analysis::wind_envelope`: global aerodynamics, the ground 10 m
//! below the origin, perfect state, Gauss-Seidel, the turbulence seeded by the bearing).
//!
//! The thrust-limited flare (`guidance::ground`, `GroundPhases::with_thrust_limit`): in a
//! 10 m/s wind the upright descent needs 130 N of the 150 N; the flare from 2 m/s over the
//! mission's 1.2 m needed 14.7 N more and the loop's lead saturated the thrust, touchdowns at
//! 0.57 m/s (headwind) and 0.78 m/s (tailwind). The flare now starts 3.8 m above the target.
//!
//! `cargo test --release -p missions --test tsdland3_wind_landing -- --nocapture` prints the
//! numbers.

use analysis::controllers::Kind;
use analysis::takeoff_landing::{self, Flight};
use analysis::wind_envelope::{StateKind, WindForm, BEARINGS_DEG};
use closed_loop::Ordering;

/// One cell flown to 5 s after the landing: the largest distance to the own reference up to
/// the touchdown and the landing's figures.
fn cell(form: WindForm, speed: f64, bearing_index: usize) -> (f64, Flight) {
    let (plant, trace) = takeoff_landing::fly_wind_cell(
        Kind::Tsd,
        form,
        StateKind::Perfect,
        Ordering::GaussSeidel,
        speed,
        bearing_index,
    );
    let mission = takeoff_landing::mission();
    let f = takeoff_landing::evaluate(&plant, Kind::Tsd, Ordering::GaussSeidel, &mission, &trace);
    let at = BEARINGS_DEG[bearing_index];
    let (td, miss, tilt) = (
        f.touchdown_speed,
        (f.miss_touchdown, f.miss_final),
        (f.tilt_touchdown_deg, f.tilt_final_deg),
    );
    println!(
        "{speed} m/s from {at}°: max error {:.2} m, landed {:?}, touchdown {td:.2} m/s, miss {miss:.2?} m (touchdown, 5 s later), tilt {tilt:.1?}°, every criterion {}",
        f.max_pos_error, f.landed_time, f.passed
    );
    (f.max_pos_error, f)
}

/// 10 m/s headwind and tailwind (steady, stepping in at 2 s): held, landed on the target
/// below 0.5 m/s upright, and still there 5 s later with the thrust cut (measured: 0.26 /
/// 0.27 m/s, 0.07 / 0.06 m from the target at the touchdown and 0.48 / 0.47 m after 5 s on
/// the gear, tilt 4.6° / 5.0°): belly-on in 10 m/s the wind's 42 N stays below the gear's
/// friction limit, and the stick-slip contact holds it.
#[test]
fn touches_down_below_half_a_metre_per_second_in_a_10_m_s_wind() {
    for bearing_index in [0, 4] {
        let (max, f) = cell(WindForm::Step, 10.0, bearing_index);
        let at = BEARINGS_DEG[bearing_index];
        assert!(max < 2.0, "{at}°: {max}");
        assert!(f.landed_time.is_some() && !f.bounced, "{at}°: {f:?}");
        assert!(f.touchdown_speed < 0.35, "{at}°: {f:?}");
        assert!(
            f.miss_touchdown < 0.2 && f.tilt_touchdown_deg < 7.0 && f.tilt_final_deg < 5.0,
            "{at}°: {f:?}"
        );
        assert!(f.passed, "{at}°: {f:?}");
    }
}

/// Moderate turbulence without and with a 3 m/s mean wind (from 270° and 180°): held and
/// every landing criterion (measured: largest error 1.09 / 1.72 m, touchdown 0.12 / 0.26 m/s,
/// 0.26 / 0.11 m from the target 5 s after the landing).
#[test]
fn lands_on_the_target_in_turbulence() {
    for (speed, bearing_index) in [(0.0, 6), (3.0, 4)] {
        let (max, f) = cell(WindForm::Turbulent, speed, bearing_index);
        let at = BEARINGS_DEG[bearing_index];
        assert!(max < 2.5, "{speed} m/s from {at}°: {max}");
        assert!(
            f.passed && f.touchdown_speed < 0.35 && f.miss_final < 0.4,
            "{speed} m/s from {at}°: {f:?}"
        );
    }
}
