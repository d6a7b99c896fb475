//! Rate controller: PID with feed-forward and the allocator's saturation feedback as
//! anti-windup (PX4 `src/lib/rate_control/rate_control.cpp`, `RateControl::update` and
//! `RateControl::updateIntegral`), shared by the multicopter and the fixed-wing loops.

use nalgebra::Vector3;

/// Rate error at which the integrator gain has fallen to zero (PX4: 400°/s, the I-term factor
/// 1 − (e / 400°/s)² of `updateIntegral`).
pub const I_FACTOR_RATE: f64 = 400.0 * core::f64::consts::PI / 180.0;

/// Gains of the three axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateGains {
    pub p: Vector3<f64>,
    pub i: Vector3<f64>,
    pub d: Vector3<f64>,
    pub ff: Vector3<f64>,
    /// Integrator limit |u_I| ≤ this.
    pub int_lim: Vector3<f64>,
}

/// One PID rate controller of three axes with its integrator state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RateControl {
    /// Integrator contribution to the torque (normalised).
    pub integral: Vector3<f64>,
    /// Saturation flags of the last allocation (positive, negative) per axis.
    pub saturated_positive: [bool; 3],
    pub saturated_negative: [bool; 3],
}

impl RateControl {
    /// Normalised torque of rate setpoint `rate_sp`, measured `rate` and angular acceleration
    /// `accel` (for the D term, on the measurement): P e + u_I − D ω̇ + FF ω_sp; then the
    /// integrator advances over `dt` (unless `frozen`, PX4's `landed`).
    pub fn update(
        &mut self,
        g: &RateGains,
        rate: &Vector3<f64>,
        rate_sp: &Vector3<f64>,
        accel: &Vector3<f64>,
        dt: f64,
        frozen: bool,
    ) -> Vector3<f64> {
        let e = rate_sp - rate;
        let torque = g.p.component_mul(&e) + self.integral - g.d.component_mul(accel) + g.ff.component_mul(rate_sp);
        if !frozen {
            self.update_integral(g, e, dt);
        }
        torque
    }

    /// Anti-windup of `updateIntegral`: no integration further into a saturated direction,
    /// the gain reduced as 1 − (e / 400°/s)² for large errors, the result clamped and only a
    /// finite one kept.
    fn update_integral(&mut self, g: &RateGains, mut e: Vector3<f64>, dt: f64) {
        for i in 0..3 {
            if self.saturated_positive[i] {
                e[i] = e[i].min(0.0);
            }
            if self.saturated_negative[i] {
                e[i] = e[i].max(0.0);
            }
            let f = e[i] / I_FACTOR_RATE;
            let i_factor = (1.0 - f * f).max(0.0);
            let next = self.integral[i] + i_factor * g.i[i] * e[i] * dt;
            if next.is_finite() {
                self.integral[i] = next.clamp(-g.int_lim[i], g.int_lim[i]);
            }
        }
    }

    /// Forget the integrator and the saturation flags.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> RateGains {
        RateGains {
            p: Vector3::repeat(0.15),
            i: Vector3::repeat(0.2),
            d: Vector3::repeat(0.003),
            ff: Vector3::zeros(),
            int_lim: Vector3::repeat(0.3),
        }
    }

    #[test]
    fn integrator_stops_in_the_saturated_direction_only() {
        let g = gains();
        let mut rc = RateControl::default();
        let sp = Vector3::new(1.0, -1.0, 0.5);
        rc.update(&g, &Vector3::zeros(), &sp, &Vector3::zeros(), 0.1, false);
        let after_one = rc.integral;
        assert!((after_one.x - 0.2 * 1.0 * 0.1 * (1.0 - (1.0 / I_FACTOR_RATE).powi(2))).abs() < 1e-12);
        // Roll saturated positive: a positive error no longer integrates, a negative one does.
        rc.saturated_positive[0] = true;
        rc.saturated_negative[1] = true;
        rc.update(&g, &Vector3::zeros(), &sp, &Vector3::zeros(), 0.1, false);
        assert_eq!(rc.integral.x, after_one.x);
        assert_eq!(rc.integral.y, after_one.y);
        assert!(rc.integral.z > after_one.z);
        rc.update(&g, &Vector3::new(2.0, 0.0, 0.0), &sp, &Vector3::zeros(), 0.1, false);
        assert!(rc.integral.x < after_one.x, "a negative error unwinds");
    }

    #[test]
    fn integrator_is_clamped_and_fades_with_large_errors() {
        let g = gains();
        let mut rc = RateControl::default();
        for _ in 0..1000 {
            rc.update(
                &g,
                &Vector3::zeros(),
                &Vector3::repeat(2.0),
                &Vector3::zeros(),
                0.02,
                false,
            );
        }
        assert!((rc.integral.x - 0.3).abs() < 1e-12, "{}", rc.integral.x);
        let mut big = RateControl::default();
        big.update(
            &g,
            &Vector3::zeros(),
            &Vector3::repeat(I_FACTOR_RATE),
            &Vector3::zeros(),
            0.02,
            false,
        );
        assert_eq!(big.integral, Vector3::zeros(), "no integration at a 400°/s error");
    }

    #[test]
    fn pid_terms() {
        let g = RateGains {
            ff: Vector3::repeat(0.5),
            ..gains()
        };
        let mut rc = RateControl::default();
        let t = rc.update(
            &g,
            &Vector3::new(0.5, 0.0, 0.0),
            &Vector3::new(1.0, 0.0, 0.0),
            &Vector3::new(10.0, 0.0, 0.0),
            0.02,
            true,
        );
        assert!((t.x - (0.15 * 0.5 - 0.003 * 10.0 + 0.5)).abs() < 1e-12);
        assert_eq!(rc.integral, Vector3::zeros(), "frozen");
    }
}
