//! Print the reference trajectory as CSV (t, V, α, θ, q, N, E, h, T, T_c, δe): the tuned
//! configuration's, or with `thesis` that of `configuration = 1` (closed forms on the cosine
//! blends, T_c = T).
use flight_mission::MissionParams;
use lqr_control::trajectory::{Trajectory, TrajectoryMode, TrajectoryOptions};
use tailsitter_physics::Airframe;

fn main() {
    let thesis = std::env::args().any(|a| a == "thesis");
    let mode = if thesis {
        TrajectoryMode::Thesis
    } else {
        TrajectoryMode::ForceBalance
    };
    let traj = Trajectory::new(
        &Airframe::default(),
        &MissionParams::default(),
        &TrajectoryOptions {
            mode,
            limited_path: !thesis,
            thrust_lead: !thesis,
            ..Default::default()
        },
    )
    .expect("trajectory");
    println!("t,V,alpha_deg,theta_deg,q_degs,N,E,h,T,T_c,de_deg");
    for p in traj.points() {
        println!(
            "{:.2},{:.4},{:.4},{:.4},{:.4},{:.3},{:.3},{:.3},{:.3},{:.3},{:.4}",
            p.t,
            p.v,
            p.alpha.to_degrees(),
            p.euler_321.y.to_degrees(),
            p.rates.y.to_degrees(),
            p.pos_neh.x,
            p.pos_neh.y,
            p.pos_neh.z,
            p.thrust,
            p.u[0],
            p.u[1].to_degrees()
        );
    }
}
