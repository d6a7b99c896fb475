//! Control allocation onto the tail-sitter's six surfaces in the spirit of PX4's control
//! allocator (`src/modules/control_allocator/ControlAllocation/ControlAllocationPseudoInverse.cpp`,
//! `ControlAllocationPseudoInverse::allocate`, and `ControlAllocator::publish_control_allocator_status`):
//! a constant effectiveness matrix B (body moments per radian of δe, δa, δr, δfc, δfd, δv),
//! its Moore–Penrose pseudo-inverse, clipping at the deflection limit, and the saturation of
//! each axis (the torque not allocated) fed back to the rate controller's anti-windup.
//!
//! PX4 takes the effectiveness from parameters (`CA_SV_CS*_TRQ_*`); here it is computed
//! from the controller's own airframe model, by central differences of the moments of
//! `tailsitter_physics::Plant::forces_moments` at a trim (hover, or level flight at the trim
//! airspeed), since PX4's effectiveness is constant, so is B per flight regime. A normalised
//! torque of 1 about an axis is the largest moment the surfaces give about that axis alone
//! at that trim (the pseudo-inverse allocation reaching the deflection limit), the scale of
//! PX4's normalised torque (README, "Control allocation").

use nalgebra::{Matrix3, Matrix3x6, Matrix6x3, Vector3, Vector6};
use tailsitter_physics::{idx, Plant, StateVector};

/// Surface order of the effectiveness columns (the plant's input order after the thrust).
pub const SURFACES: [usize; 6] = [
    idx::ELEVATOR,
    idx::AILERON,
    idx::RUDDER,
    idx::FLAP_COLLECTIVE,
    idx::FLAP_DIFFERENTIAL,
    idx::VERTICAL_FLAP,
];

/// The effectiveness of one flight regime and what the allocation derives from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effectiveness {
    /// B: body moment (N m) per radian of each surface.
    pub b: Matrix3x6<f64>,
    /// B⁺ = Bᵀ (B Bᵀ)⁻¹.
    pub b_pinv: Matrix6x3<f64>,
    /// Moment of a normalised torque of 1 about each body axis (N m).
    pub scale: Vector3<f64>,
    /// Deflection limit (rad).
    pub limit: f64,
}

/// The allocated deflections and the saturation of each body axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Allocation {
    /// δe, δa, δr, δfc, δfd, δv (rad).
    pub deflections: Vector6<f64>,
    /// Per body axis: the torque left unallocated is positive / negative.
    pub saturated_positive: [bool; 3],
    pub saturated_negative: [bool; 3],
}

impl Effectiveness {
    /// B of `plant` at state `x` (central differences of ±1 mrad), its pseudo-inverse and
    /// the normalisation; `None` if B Bᵀ is singular or a value is not finite.
    pub fn at(plant: &Plant, x: &StateVector, limit: f64) -> Option<Self> {
        let h = 1e-3;
        let mut b = Matrix3x6::zeros();
        let zero = Vector3::zeros();
        for (j, &k) in SURFACES.iter().enumerate() {
            let (mut xp, mut xm) = (*x, *x);
            xp[k] += h;
            xm[k] -= h;
            let d = (plant.forces_moments(&xp, &zero).moment_body - plant.forces_moments(&xm, &zero).moment_body)
                / (2.0 * h);
            b.set_column(j, &d);
        }
        let bbt: Matrix3<f64> = b * b.transpose();
        let b_pinv = b.transpose() * bbt.try_inverse()?;
        let mut scale = Vector3::zeros();
        for i in 0..3 {
            let worst = b_pinv.column(i).amax();
            scale[i] = limit / worst;
        }
        (b.iter().chain(b_pinv.iter()).chain(scale.iter()).all(|v| v.is_finite())).then_some(Self {
            b,
            b_pinv,
            scale,
            limit,
        })
    }

    /// Deflections of the normalised body torque `torque` (per axis: fraction of
    /// [`Self::scale`]) on top of `trim` deflections: u = u_trim + B⁺ τ, each clipped to the
    /// limit; an axis is saturated in the sign of the moment the clipping left unallocated.
    pub fn allocate(&self, torque: &Vector3<f64>, trim: &Vector6<f64>) -> Allocation {
        let tau = torque.component_mul(&self.scale);
        let u = trim + self.b_pinv * tau;
        let clipped = u.map(|d| d.clamp(-self.limit, self.limit));
        let missing = tau - self.b * (clipped - trim);
        let mut pos = [false; 3];
        let mut neg = [false; 3];
        for i in 0..3 {
            let tol = 1e-6 * self.scale[i];
            pos[i] = missing[i] > tol;
            neg[i] = missing[i] < -tol;
        }
        Allocation {
            deflections: clipped,
            saturated_positive: pos,
            saturated_negative: neg,
        }
    }

    /// The normalised body torque that deflections `u` make (B u / scale).
    pub fn torque_of(&self, u: &Vector6<f64>) -> Vector3<f64> {
        (self.b * u).component_div(&self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tailsitter_physics::Airframe;

    fn hover() -> Effectiveness {
        let plant = Plant::new(Airframe::default());
        let trim = plant.trim_vertical_climb(3.0).unwrap();
        Effectiveness::at(&plant, &trim.state, Airframe::default().deflection_limit).unwrap()
    }

    #[test]
    fn allocation_inverts_the_effectiveness_inside_the_limits() {
        let e = hover();
        let tau = Vector3::new(0.3, -0.5, 0.2);
        let a = e.allocate(&tau, &Vector6::zeros());
        assert!((e.torque_of(&a.deflections) - tau).norm() < 1e-9);
        assert_eq!((a.saturated_positive, a.saturated_negative), ([false; 3], [false; 3]));
        // A unit torque about one axis reaches the deflection limit exactly.
        for i in 0..3 {
            let a = e.allocate(&Vector3::ith(i, 1.0), &Vector6::zeros());
            assert!((a.deflections.amax() - e.limit).abs() < 1e-12);
        }
    }

    #[test]
    fn saturation_is_clipped_and_flagged_per_axis() {
        let e = hover();
        let a = e.allocate(&Vector3::new(0.0, 3.0, 0.0), &Vector6::zeros());
        assert!(a.deflections.amax() <= e.limit + 1e-15);
        assert!(a.saturated_positive[1] && !a.saturated_negative[1], "{a:?}");
        let achieved = e.torque_of(&a.deflections);
        assert!(achieved.y > 0.99 && achieved.y < 3.0, "{achieved}");
        let a = e.allocate(&Vector3::new(0.0, -3.0, 0.0), &Vector6::zeros());
        assert!(a.saturated_negative[1] && !a.saturated_positive[1]);
    }

    #[test]
    fn hover_effectiveness_has_the_expected_signs() {
        // In the hover the slip-stream surfaces act; the ailerons (free stream) hardly.
        let e = hover();
        assert!(e.b[(1, 0)] < 0.0, "δe > 0 pitches nose down: C_mδe < 0");
        assert!(
            e.b.column(1).norm() < 0.05 * e.b.column(4).norm(),
            "ailerons vs differential flaps: {}",
            e.b
        );
        assert!(e.scale.iter().all(|s| *s > 0.0));
    }
}
