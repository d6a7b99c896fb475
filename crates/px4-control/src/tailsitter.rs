//! The tail-sitter's VTOL mode logic and transitions (PX4
//! `src/modules/vtol_att_control/tailsitter.cpp`, `Tailsitter::update_vtol_state` and
//! `Tailsitter::update_transition_state`):
//!
//! * front transition on the fixed-wing request: the attitude setpoint starts wings level
//!   at the multicopter setpoint's pitch and yaw and turns about the horizontal axis
//!   perpendicular to the belly at π/2 / VT_F_TRANS_DUR until the tilt reaches
//!   π/2 − FW_PSP_OFF; fixed-wing flight begins once the multicopter pitch is below
//!   −1.1 rad (63° over) and the airspeed is at least VT_ARSP_TRANS;
//! * back transition on the multicopter request: the setpoint starts at the fixed-wing
//!   pitch setpoint and the nose's heading, wings level, and turns up at
//!   π/2 / VT_B_TRANS_DUR until upright; multicopter flight resumes once the multicopter
//!   pitch is above −0.25 rad or after VT_B_TRANS_DUR;
//! * a request reversed in mid-transition falls back to the mode it came from.
//!
//! Attitudes in the multicopter frame (README, "Frames"), as PX4's transitions are flown by
//! the multicopter attitude controller.

use crate::{body_from_mc, Derived, Reference};
use nalgebra::{Quaternion, Unit, UnitQuaternion, Vector3};

/// Multicopter pitch below which the front transition may end (PX4 `PITCH_TRANSITION_FRONT_P1`) (rad).
pub const PITCH_TRANSITION_FRONT: f64 = -1.1;
/// Multicopter pitch above which the back transition ends (PX4 `PITCH_TRANSITION_BACK`) (rad).
pub const PITCH_TRANSITION_BACK: f64 = -0.25;

/// PX4's tail-sitter flight modes (`vtol_mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VtolMode {
    #[default]
    Multicopter = 0,
    FrontTransition = 1,
    FixedWing = 2,
    BackTransition = 3,
}

impl VtolMode {
    fn from_code(c: f64) -> Option<Self> {
        if c.fract() != 0.0 {
            return None;
        }
        Some(match c as i64 {
            0 => Self::Multicopter,
            1 => Self::FrontTransition,
            2 => Self::FixedWing,
            3 => Self::BackTransition,
            _ => return None,
        })
    }
}

/// State of the mode logic and the transition setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vtol {
    pub mode: VtolMode,
    /// Start time of the transition in progress (s).
    pub start: f64,
    pub q_start: UnitQuaternion<f64>,
    pub q_sp: UnitQuaternion<f64>,
    /// Rotation axis of the ramp (unit, earth axes).
    pub axis: Vector3<f64>,
    /// Last multicopter attitude setpoint (multicopter frame).
    pub mc_sp: UnitQuaternion<f64>,
    /// Last fixed-wing pitch setpoint (rad) and heading (rad).
    pub fw_pitch_sp: f64,
    pub fw_yaw: f64,
}

impl Default for Vtol {
    fn default() -> Self {
        Self {
            mode: VtolMode::Multicopter,
            start: 0.0,
            q_start: UnitQuaternion::identity(),
            q_sp: UnitQuaternion::identity(),
            axis: Vector3::new(0.0, -1.0, 0.0),
            mc_sp: UnitQuaternion::identity(),
            fw_pitch_sp: 0.0,
            fw_yaw: 0.0,
        }
    }
}

/// `v` as a unit axis, or `fallback` if it is (nearly) zero.
fn unit_or(v: Vector3<f64>, fallback: Vector3<f64>) -> Vector3<f64> {
    if v.norm() > 1e-6 {
        v.normalize()
    } else {
        fallback
    }
}

/// Tilt of an attitude: the angle between its z axis and the earth's down axis.
fn tilt(q: &UnitQuaternion<f64>) -> f64 {
    (q * Vector3::z()).z.clamp(-1.0, 1.0).acos()
}

impl Vtol {
    /// Number of values [`Self::save`] writes.
    pub const SAVED_LEN: usize = 2 + 4 + 4 + 3 + 4 + 2;

    /// The mode at time `t` for reference `r`, multicopter-frame attitude `q_mc` and
    /// airspeed (`update_vtol_state`); starts a transition's ramp on entry.
    pub fn update(
        &mut self,
        t: f64,
        r: &Reference,
        q_mc: &UnitQuaternion<f64>,
        airspeed: f64,
        d: &Derived,
    ) -> VtolMode {
        let pitch = q_mc.euler_angles().1;
        let down_up = Vector3::new(0.0, 0.0, -1.0);
        self.mode = match (r.fixed_wing, self.mode) {
            (true, VtolMode::Multicopter) => {
                // Wings level at the multicopter setpoint's pitch and yaw; the axis turns the
                // belly (x_mc) down towards the path.
                let (_, sp_pitch, sp_yaw) = self.mc_sp.euler_angles();
                self.q_start = UnitQuaternion::from_euler_angles(0.0, sp_pitch, sp_yaw);
                let x = q_mc * Vector3::x();
                self.axis = unit_or(-x.cross(&down_up), Vector3::new(0.0, -1.0, 0.0));
                self.q_sp = self.q_start;
                self.start = t;
                VtolMode::FrontTransition
            }
            (true, VtolMode::FrontTransition) => {
                if pitch <= PITCH_TRANSITION_FRONT && airspeed >= d.transition_airspeed {
                    VtolMode::FixedWing
                } else {
                    VtolMode::FrontTransition
                }
            }
            (true, _) => VtolMode::FixedWing,
            (false, VtolMode::FixedWing) => {
                // The thrust axis (the nose) gives the heading; the ramp turns it up.
                let z = -(q_mc * Vector3::z());
                let yaw = z.y.atan2(z.x);
                let fw = UnitQuaternion::from_euler_angles(0.0, self.fw_pitch_sp, yaw);
                self.q_start = fw * body_from_mc();
                self.axis = unit_or(z.cross(&down_up), Vector3::new(0.0, 1.0, 0.0));
                self.q_sp = self.q_start;
                self.start = t;
                VtolMode::BackTransition
            }
            (false, VtolMode::BackTransition) => {
                if pitch >= PITCH_TRANSITION_BACK || t - self.start > d.back_duration {
                    VtolMode::Multicopter
                } else {
                    VtolMode::BackTransition
                }
            }
            (false, _) => VtolMode::Multicopter,
        };
        self.mode
    }

    /// The transition's attitude setpoint at `t` (`update_transition_state`): the start
    /// attitude turned about the axis by (t − start) · π/2 / duration while the tilt is
    /// short of the end (front: π/2 − FW_PSP_OFF; back: upright).
    pub fn transition_setpoint(&mut self, t: f64, d: &Derived) -> UnitQuaternion<f64> {
        let tilt = tilt(&self.q_sp);
        let axis = Unit::new_unchecked(self.axis);
        let half_pi = core::f64::consts::FRAC_PI_2;
        match self.mode {
            VtolMode::FrontTransition if tilt < half_pi - d.pitch_offset => {
                let angle = (t - self.start) * half_pi / d.front_duration;
                self.q_sp = UnitQuaternion::from_axis_angle(&axis, angle) * self.q_start;
            }
            VtolMode::BackTransition if tilt > 0.01 => {
                let angle = (t - self.start) * half_pi / d.back_duration;
                self.q_sp = UnitQuaternion::from_axis_angle(&axis, angle) * self.q_start;
            }
            _ => {}
        }
        self.q_sp
    }

    pub fn save(&self, out: &mut impl FnMut(f64)) {
        out(self.mode as i32 as f64);
        out(self.start);
        for q in [&self.q_start, &self.q_sp] {
            for c in q.coords.iter() {
                out(*c);
            }
        }
        for v in self.axis.iter() {
            out(*v);
        }
        for c in self.mc_sp.coords.iter() {
            out(*c);
        }
        out(self.fw_pitch_sp);
        out(self.fw_yaw);
    }

    /// Restore what [`Self::save`] wrote; `None` if a value is missing, the mode invalid or a
    /// quaternion or axis not finite and non-zero.
    pub fn restore(&mut self, next: &mut impl FnMut() -> Option<f64>) -> Option<()> {
        let mode = VtolMode::from_code(next()?)?;
        let start = next()?;
        let quat = |next: &mut dyn FnMut() -> Option<f64>| -> Option<UnitQuaternion<f64>> {
            let (x, y, z, w) = (next()?, next()?, next()?, next()?);
            let q = Quaternion::new(w, x, y, z);
            (q.norm() > 1e-6 && q.norm().is_finite()).then(|| UnitQuaternion::from_quaternion(q))
        };
        let q_start = quat(next)?;
        let q_sp = quat(next)?;
        let axis = Vector3::new(next()?, next()?, next()?);
        if !(axis.norm() > 1e-6 && axis.norm().is_finite()) {
            return None;
        }
        let mc_sp = quat(next)?;
        let (fw_pitch_sp, fw_yaw) = (next()?, next()?);
        if !(start.is_finite() && fw_pitch_sp.is_finite() && fw_yaw.is_finite()) {
            return None;
        }
        *self = Self {
            mode,
            start,
            q_start,
            q_sp,
            axis: axis.normalize(),
            mc_sp,
            fw_pitch_sp,
            fw_yaw,
        };
        Some(())
    }
}
