//! Riccati solvers on the aircraft's own linearised, discretised model: the thesis's
//! backward iteration converges to the steady-state DARE gain as N grows; the DARE
//! solution satisfies its equation (timing: `cargo bench -p lqr-control`).

use flight_mission::MissionParams;
use lqr_control::linalg::{dare_residual, dare_sda, lqr_gain, riccati_backward, spectral_radius_bound};
use lqr_control::model::EulerRep;
use lqr_control::{LqrController, LqrParams};
use nalgebra::SMatrix;
use tailsitter_physics::Airframe;

fn setup(
    t: f64,
) -> (
    LqrController,
    lqr_control::GainSolution,
    SMatrix<f64, { lqr_control::model::NA }, { lqr_control::model::NA }>,
    nalgebra::SVector<f64, 7>,
) {
    let m = MissionParams::default();
    let c = LqrController::new(Airframe::default(), m, LqrParams::default()).unwrap();
    let p = c.trajectory().at(t);
    let rep = if p.euler_321.y > 0.8 {
        EulerRep::E231
    } else {
        EulerRep::E321
    };
    let sol = c.solve_gain(rep, &p.state(rep), &p.u, t).unwrap();
    let w = c.schedule().at(&m, t);
    (c, sol, SMatrix::from_diagonal(&w.q), w.r)
}

#[test]
fn backward_iteration_converges_to_the_dare_gain() {
    for t in [2.0, 15.0, 7.0] {
        let (_, sol, q, r) = setup(t);
        let p = dare_sda(&sol.phi, &sol.gamma, &q, &r).unwrap();
        let k = lqr_gain(&sol.phi, &sol.gamma, &p, &r).unwrap();
        let res = dare_residual(&sol.phi, &sol.gamma, &q, &p, &k);
        assert!(res < 1e-9, "t = {t}: residual {res}");
        let mut last = f64::INFINITY;
        print!(
            "t = {t:4.1} s, ρ(Φ−ΓK) = {:.5}; ‖K_N − K‖/‖K‖:",
            spectral_radius_bound(&(sol.phi - sol.gamma * k))
        );
        for n in [50, 200, 1000, 5000, 20000, 60000] {
            let (kn, _) = riccati_backward(&sol.phi, &sol.gamma, &q, &r, n, None).unwrap();
            let err = (kn - k).norm() / k.norm();
            print!(" N={n}: {err:.2e}");
            assert!(err <= last * 1.001 + 1e-12, "t = {t}: not converging at N = {n}");
            last = err;
        }
        println!();
        assert!(last < 1e-8, "t = {t}: {last}");
    }
}
