//! The fast DARE ([`dare_sda`]: fused multiply-adds, symmetric half products) gives the
//! gains of a plain textbook SDA-1 (nalgebra products, full matrices, separate multiply and
//! add: the arithmetic of the solver before issue 17's last pass) to 1e-8 relative
//! (issue 17's bar) on the aircraft's own 17×17 / 17×7 problems along the default mission.

use flight_mission::MissionParams;
use lqr_control::linalg::{dare_sda, lqr_gain};
use lqr_control::model::{EulerRep, NA, NU};
use lqr_control::{LqrController, LqrParams};
use nalgebra::{SMatrix, SVector};
use tailsitter_physics::Airframe;

/// SDA-1 (Chu, Fan, Lin 2005) in plain nalgebra, same stopping rule as `dare_sda`.
fn sda_plain(
    phi: &SMatrix<f64, NA, NA>,
    gamma: &SMatrix<f64, NA, NU>,
    q: &SMatrix<f64, NA, NA>,
    r: &SVector<f64, NU>,
) -> SMatrix<f64, NA, NA> {
    let rinv = SMatrix::<f64, NU, NU>::from_diagonal(&r.map(|v| 1.0 / v));
    let mut g = gamma * rinv * gamma.transpose();
    let mut a = *phi;
    let mut h = *q;
    for _ in 0..60 {
        let w = SMatrix::<f64, NA, NA>::identity() + g * h;
        let lu = w.lu();
        let x1 = lu.solve(&a).unwrap();
        let x2 = lu.solve(&g).unwrap();
        let h_new = h + a.transpose() * h * x1;
        g += a * x2 * a.transpose();
        a *= x1;
        let change = (h_new - h).norm();
        h = h_new;
        if change <= 1e-13 * h.norm() || a.norm_squared() <= 1e-13 {
            return h;
        }
    }
    panic!("plain SDA did not converge");
}

#[test]
fn fast_dare_gains_equal_plain_sda_gains() {
    let m = MissionParams::default();
    let params = LqrParams::default();
    let c = LqrController::new(Airframe::default(), m, params.clone()).unwrap();
    let mut worst: f64 = 0.0;
    for t in [0.5, 2.0, 6.0, 10.0, 15.0, 20.0, 26.0, 32.0] {
        let p = c.trajectory().at(t);
        let rep = if p.euler_321.y > params.euler_switch_pitch {
            EulerRep::E231
        } else {
            EulerRep::E321
        };
        let sol = c.solve_gain(rep, &p.state(rep), &p.u, t).unwrap();
        let w = c.schedule().at(&m, t);
        let q = SMatrix::<f64, NA, NA>::from_diagonal(&w.q);
        let fast = dare_sda(&sol.phi, &sol.gamma, &q, &w.r).unwrap();
        let plain = sda_plain(&sol.phi, &sol.gamma, &q, &w.r);
        let k_fast = lqr_gain(&sol.phi, &sol.gamma, &fast, &w.r).unwrap();
        let k_plain = lqr_gain(&sol.phi, &sol.gamma, &plain, &w.r).unwrap();
        let err = (k_fast - k_plain).amax() / k_plain.amax();
        println!(
            "t = {t} s ({rep:?}): gains differ by {err:.1e} relative, P by {:.1e}",
            (fast - plain).amax() / plain.amax()
        );
        worst = worst.max(err);
        assert_eq!(fast, fast.transpose(), "P exactly symmetric");
    }
    assert!(worst <= 1e-8, "worst gain difference {worst:e}");
}
