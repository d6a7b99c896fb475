//! The tuned TSD's take-off-to-landing mission (`analysis::takeoff_landing::mission`) in a
//! steady wind stepping in at 2 s, the cells of the wind envelope (`analysis::wind_envelope`:
//! global aerodynamics, the ground 10 m below the origin, Gauss-Seidel, perfect state).
//!
//! The take-off and landing phases in wind (tsd-control README, "Take-off and landing in
//! wind"): the belly into the measured wind (engaged from 2 m/s), the hover-in-wind design,
//! the collective flaps' direct force (trim and lean feedback). Without them every cell from
//! 5 m/s was lost in the descent and at 3 m/s the aircraft touched down leaning 30° into the
//! wind; without the lean feedback it touched down leaning 20–23° into 5 m/s, and without the
//! lower engage speed 12° in a quartering 3 m/s wind.
//!
//! `cargo test --release -p missions --test tsd_wind_landing -- --nocapture` prints the numbers.

#[path = "support/tl_cell.rs"]
mod tl_cell;

use analysis::controllers::Kind;
use analysis::takeoff_landing::Flight;
use analysis::wind_envelope::{WindForm, BEARINGS_DEG};

/// The largest distance to the own reference and the landing's figures of one cell.
fn cell(speed: f64, bearing_index: usize) -> (f64, Flight) {
    tl_cell::fly_cell(Kind::Tsd, WindForm::Step, speed, bearing_index)
}

/// 3 m/s across the track (from the east) and quartering (from the north-east): every
/// landing criterion, upright (measured: largest error 1.44 / 1.91 m, miss 0.07 / 0.06 m,
/// 0.14 m/s, tilt 3.5° / 3.2° at touchdown).
#[test]
fn lands_upright_on_the_target_in_a_3_m_s_crosswind_and_quartering_wind() {
    for bearing_index in [2, 1] {
        let (max, f) = cell(3.0, bearing_index);
        assert!(max < 2.5, "{}°: {max}", BEARINGS_DEG[bearing_index]);
        assert!(
            f.passed && f.tilt_touchdown_deg < 5.0 && f.miss_final < 0.2,
            "{}°: {f:?}",
            BEARINGS_DEG[bearing_index]
        );
    }
}

/// 5 m/s headwind and 8 m/s tailwind: held (< 3 m from the own reference) and every landing
/// criterion, upright (measured: largest error 1.65 / 1.56 m, miss 0.06 / 0.17 m, 0.13 /
/// 0.10 m/s, tilt 6.2° / 6.6° at touchdown, 0.5° / 1.2° 5 s later).
#[test]
fn lands_upright_on_the_target_in_a_5_m_s_headwind_and_an_8_m_s_tailwind() {
    for (speed, bearing_index) in [(5.0, 0), (8.0, 4)] {
        let (max, f) = cell(speed, bearing_index);
        assert!(max < 2.0, "{speed} m/s: {max}");
        assert!(
            f.passed && f.miss_final < 0.3 && f.touchdown_speed < 0.3 && f.tilt_touchdown_deg < 8.0,
            "{speed} m/s: {f:?}"
        );
    }
}
