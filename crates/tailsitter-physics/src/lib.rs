//! Pure-Rust nonlinear 6-DOF model of the tail-sitter VTOL aircraft of S.C. Kriel's thesis
//! *A Comparison of Control Systems for the Flight Transition of VTOL Unmanned Aerial
//! Vehicles* (ch. 2, App. A, C, D).
//!
//! * [`Airframe`]: parameters (App. C, docs/DESIGN.md §4) and the force/moment model
//!   [`Airframe::forces_moments`] (§2.3) that controllers use for their own models.
//! * [`Plant`]: the 20-state plant: derivatives, fixed-step Runge–Kutta [`Plant::advance`], outputs,
//!   trims ([`Plant::trim_level`], [`Plant::trim_vertical_climb`]) and [`Plant::linearise`].
//! * [`attitude`]: quaternion (A.2.8, scalar last), DCMs and Euler angles (3-2-1, 2-3-1).
//! * [`Site`]: the reference point of the local NED frame and the Earth's magnetic field there
//!   (shared by the sensor model and the state estimator).
//!
//! Frames: earth NED (treated as inertial), body (x forward/nose — up in hover — y right
//! wing, z down), wind (x along the air-relative velocity, A.2.7). SI units, angles in rad.
//! See README.md for the equations and the thesis typos corrected here.

#![allow(non_snake_case)]

pub mod aero;
pub mod aero_jacobian;
pub mod airframe;
pub mod attitude;
pub mod error;
pub mod global_aero;
pub mod ground;
pub mod numeric;
pub mod plant;
pub mod site;

pub use aero::{ForcesMoments, Surfaces, AIRSPEED_EPS};
pub use aero_jacobian::{FmJacobian, N_FM_ARGS};
pub use airframe::{Airframe, Coefficients, InvalidParameter};
pub use attitude::{
    dcm_earth_to_body, dcm_from_euler_231, euler_231, euler_231_from_quat, euler_321_from_quat, pitch_321,
    quat_derivative, quat_from_dcm, quat_from_euler_231, quat_from_euler_321,
};
pub use error::PhysicsError;
pub use global_aero::{AeroDiagnostics, AeroModel, AeroRegime, GlobalAero};
pub use ground::{Anchor, ContactAnchors, ContactState, Grip, Ground};
pub use plant::{
    dp5, Envelope, Integrator, Outputs, Plant, Trim, DEFAULT_INTEGRATION_STEP, MAX_CHECKED_SUBSTEPS, MAX_SUBSTEPS,
};
pub use site::Site;

use nalgebra::SVector;

/// Number of states: position 3, velocity 3, quaternion 4, rates 3, thrust 1, servos 6.
pub const N_STATES: usize = 20;
/// Number of command inputs.
pub const N_INPUTS: usize = 7;
/// The plant state, indexed by [`idx`].
pub type StateVector = SVector<f64, N_STATES>;
/// The commands, indexed by [`idx`] (`*_CMD`).
pub type InputVector = SVector<f64, N_INPUTS>;

/// Indices into [`StateVector`] and [`InputVector`].
pub mod idx {
    /// North position of the CG (m) (earth, NED).
    pub const POS_N: usize = 0;
    /// East position (m).
    pub const POS_E: usize = 1;
    /// Down position (m).
    pub const POS_D: usize = 2;
    /// Inertial velocity, body x component (m/s).
    pub const U: usize = 3;
    /// Inertial velocity, body y component (m/s).
    pub const V: usize = 4;
    /// Inertial velocity, body z component (m/s).
    pub const W: usize = 5;
    /// Quaternion q1 (A.2.8, vector part x).
    pub const Q1: usize = 6;
    /// Quaternion q2.
    pub const Q2: usize = 7;
    /// Quaternion q3.
    pub const Q3: usize = 8;
    /// Quaternion q4 (scalar part).
    pub const Q4: usize = 9;
    /// Roll rate p (rad/s).
    pub const P: usize = 10;
    /// Pitch rate q (rad/s).
    pub const Q: usize = 11;
    /// Yaw rate r (rad/s).
    pub const R: usize = 12;
    /// Thrust state T (N) (2.3.16).
    pub const THRUST: usize = 13;
    /// Elevator deflection δe (rad).
    pub const ELEVATOR: usize = 14;
    /// Aileron deflection δa (rad).
    pub const AILERON: usize = 15;
    /// Rudder deflection δr (rad).
    pub const RUDDER: usize = 16;
    /// Collective flap deflection δfc (rad).
    pub const FLAP_COLLECTIVE: usize = 17;
    /// Differential flap deflection δfd (rad).
    pub const FLAP_DIFFERENTIAL: usize = 18;
    /// Vertical flap deflection δv (rad).
    pub const VERTICAL_FLAP: usize = 19;
    /// First of the six servo states (δe, δa, δr, δfc, δfd, δv consecutive).
    pub const SURFACES: usize = ELEVATOR;

    /// Commanded thrust T_c (N).
    pub const THRUST_CMD: usize = 0;
    /// Commanded δe (rad).
    pub const ELEVATOR_CMD: usize = 1;
    /// Commanded δa (rad).
    pub const AILERON_CMD: usize = 2;
    /// Commanded δr (rad).
    pub const RUDDER_CMD: usize = 3;
    /// Commanded δfc (rad).
    pub const FLAP_COLLECTIVE_CMD: usize = 4;
    /// Commanded δfd (rad).
    pub const FLAP_DIFFERENTIAL_CMD: usize = 5;
    /// Commanded δv (rad).
    pub const VERTICAL_FLAP_CMD: usize = 6;
    /// First of the six surface commands.
    pub const SURFACES_CMD: usize = ELEVATOR_CMD;

    /// State names (FMU output names), by index.
    pub const STATE_NAMES: [&str; super::N_STATES] = [
        "pos_n",
        "pos_e",
        "pos_d",
        "u",
        "v",
        "w",
        "quat_1",
        "quat_2",
        "quat_3",
        "quat_4",
        "p",
        "q",
        "r",
        "thrust",
        "elevator",
        "aileron",
        "rudder",
        "flap_collective",
        "flap_differential",
        "vertical_flap",
    ];
    include!(concat!(env!("OUT_DIR"), "/input_names.rs"));
    const _: () = assert!(INPUT_NAMES.len() == super::N_INPUTS);
}
