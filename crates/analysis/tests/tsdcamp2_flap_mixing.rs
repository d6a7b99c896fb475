//! A campaign run the collective flaps' mixing factor in wind holds (tuned TSD, native
//! engine, perfect state): the jobs of `analysis campaign-jobs`, as the 200-sample campaigns
//! of seeds 1 and 2 wrote them (tsdcamp2_flap_mixing_jobs.jsonl). With the printed factor 1.1
//! in every phase, seed 1's sample 88 (C_Lδe × 0.75, C_Yδr × 1.15, 9.1 m/s steady wind) left
//! the 50 m divergence bound in level flight and seed 2's sample 105 (C_Lδe × 1.32, 9.0 m/s
//! wind, moderate turbulence) reached 14.9 m in the back transition. The factor held that
//! one at 1.53 m, but with the hover's normal poles slowed in gusts it is lost again (50 m at
//! 19.6 s): not asserted.

use analysis::native_campaign::{run, Job};

fn job(key_prefix: &str) -> Job {
    include_str!("tsdcamp2_flap_mixing_jobs.jsonl")
        .lines()
        .map(|l| serde_json::from_str::<Job>(l).expect("a job"))
        .find(|j| j.key.starts_with(key_prefix))
        .expect("the job")
}

fn check(key_prefix: &str, limit: f64) {
    let row = run(&job(key_prefix));
    let max_err = row.metrics["max_err"].unwrap_or(f64::NAN);
    println!(
        "{key_prefix}: {} {} largest error {max_err:.2} m",
        row.completed, row.failure
    );
    assert!(row.completed, "{key_prefix}: {} {}", row.failure, row.detail);
    assert!(max_err < limit, "{key_prefix}: largest error {max_err:.2} m");
}

#[test]
fn level_flight_in_a_9_m_s_wind_is_held() {
    // 2.40 m with the wind factor.
    check("s1-88/", 3.0);
}
