//! The estimator's model of the motor and the servos, driven by the commands: the same
//! equations and parameters ([`Airframe`]) as the plant (`Plant::derivatives`), integrated
//! exactly over a step with the command held.
//!
//! * Thrust lag (2.3.16): Ṫ = (sat(T_c) − T)/τ_T ⇒ T(t+h) = T_c + (T − T_c) e^{−h/τ_T}.
//! * Servo (App. D.5): δ̇ = sat_{±r}((sat_{±δmax}(δ_c) − δ)/τ_s): slews at the rate limit r
//!   while |δ_c − δ| > r τ_s, then decays exponentially.

use tailsitter_physics::{idx, Airframe, InputVector};

/// Thrust state and the six deflections in [`tailsitter_physics::Surfaces`] order
/// (elevator, aileron, rudder, flap collective, flap differential, vertical flap).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Actuators {
    /// Thrust T of both propellers (N).
    pub thrust: f64,
    /// Actual deflections (rad).
    pub surfaces: [f64; 6],
}

impl Actuators {
    /// The steady state under the commands `u` (thrust = sat(T_c), deflections = sat(δ_c)):
    /// what the plant's trims start from.
    pub fn steady(a: &Airframe, u: &InputVector) -> Self {
        let mut s = [0.0; 6];
        for (k, d) in s.iter_mut().enumerate() {
            *d = u[idx::SURFACES_CMD + k].clamp(-a.deflection_limit, a.deflection_limit);
        }
        Self {
            thrust: u[idx::THRUST_CMD].clamp(a.thrust_min, a.thrust_max),
            surfaces: s,
        }
    }

    /// The state the estimator starts from: thrust `thrust` and elevator `elevator`, the
    /// other surfaces 0, each within its limits (the steady state of those commands).
    pub fn initial(a: &Airframe, thrust: f64, elevator: f64) -> Self {
        let mut u = InputVector::zeros();
        u[idx::THRUST_CMD] = thrust;
        u[idx::ELEVATOR_CMD] = elevator;
        Self::steady(a, &u)
    }

    /// Advance by `h` (s) with the commands `u` held.
    pub fn advance(&mut self, a: &Airframe, u: &InputVector, h: f64) {
        let tc = u[idx::THRUST_CMD].clamp(a.thrust_min, a.thrust_max);
        self.thrust = (tc + (self.thrust - tc) * (-h / a.tau_thrust).exp()).clamp(a.thrust_min, a.thrust_max);
        let lim = a.deflection_limit;
        for (k, d) in self.surfaces.iter_mut().enumerate() {
            let c = u[idx::SURFACES_CMD + k].clamp(-lim, lim);
            *d = servo_step(*d, c, a.servo_tau, a.servo_rate_limit, h).clamp(-lim, lim);
        }
    }
}

/// Exact solution of δ̇ = sat_{±rate}((c − δ)/τ) over `h` from `d`.
fn servo_step(d: f64, c: f64, tau: f64, rate: f64, h: f64) -> f64 {
    let e = c - d;
    let band = rate * tau;
    let mut rest = h;
    let mut e1 = e;
    if e.abs() > band {
        // Slew at the rate limit until |e| = r τ.
        let t1 = (e.abs() - band) / rate;
        if t1 >= h {
            return d + e.signum() * rate * h;
        }
        rest = h - t1;
        e1 = e.signum() * band;
    }
    c - e1 * (-rest / tau).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use tailsitter_physics::Plant;

    /// The exact solution follows the plant's RK4 integration of the same ODE (2 ms steps)
    /// through slewing, the kink and the exponential tail, for a sequence of held commands.
    #[test]
    fn follows_the_plants_actuator_states() {
        let a = Airframe::default();
        let plant = Plant::new(a);
        let mut x = plant.trim_vertical_climb(3.0).unwrap().state;
        let u0 = plant.trim_vertical_climb(3.0).unwrap().inputs;
        let mut act = Actuators::steady(&a, &u0);
        assert!((act.thrust - x[idx::THRUST]).abs() < 1e-9);
        let wind = Vector3::zeros();
        for k in 0..60 {
            let mut u = u0;
            // Elevator steps of 0.7 rad (> r τ = 0.435 rad: slewing first) to a command
            // beyond the deflection limit, and a ramp on the aileron.
            u[idx::THRUST_CMD] = if (k / 10) % 2 == 0 { 120.0 } else { 70.0 };
            u[idx::ELEVATOR_CMD] = if (k / 7) % 2 == 0 { 0.6 } else { -0.1 };
            u[idx::AILERON_CMD] = 0.02 * k as f64 - 0.5;
            plant.advance(&mut x, &u, &wind, 0.02).unwrap();
            act.advance(&a, &u, 0.02);
            assert!((act.thrust - x[idx::THRUST]).abs() < 1e-6, "k = {k}: thrust");
            for s in 0..6 {
                assert!(
                    (act.surfaces[s] - x[idx::SURFACES + s]).abs() < 2e-4,
                    "k = {k}, surface {s}: {} vs {}",
                    act.surfaces[s],
                    x[idx::SURFACES + s]
                );
            }
        }
    }

    #[test]
    fn servo_slews_at_the_rate_limit() {
        // From 0 to 0.4 rad with r = 8.7 rad/s, τ = 0.05 s: slewing while |e| > 0.435 rad
        // never happens for 0.4; from 0 to 1.0 (above r τ) it slews 0.087 rad in 10 ms.
        let d = servo_step(0.0, 1.0, 0.05, 8.7, 0.01);
        assert!((d - 0.087).abs() < 1e-12);
        // Inside the band: pure exponential.
        let d = servo_step(0.0, 0.4, 0.05, 8.7, 0.05);
        assert!((d - 0.4 * (1.0 - (-1.0f64).exp())).abs() < 1e-12);
    }
}
