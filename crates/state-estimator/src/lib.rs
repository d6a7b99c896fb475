//! State estimator of the tail-sitter (thesis App. D.4): an error-state extended Kalman
//! filter fusing GPS (position, velocity), IMU (specific force, rates), magnetometer and
//! pitot, estimating position, velocity, attitude, gyro and accelerometer biases and the
//! wind; plus the estimator's models of the motor and servos driven by the commands.
//!
//! Pure Rust, no FFI, statically sized matrices, no allocation per step. The FMU binding is
//! `fmu-ekf` (`tailsitter_ekf`). See the crate README for the design and the tuning.

pub mod actuators;
pub mod bound;
pub mod ekf;
pub mod geodesy;
pub mod params;

pub use actuators::Actuators;
pub use ekf::{
    attitude_error, rotation_exp, rotation_log, Covariance, Ekf, Estimate, FilterState, InitReport, Measurements,
    Reason, Rejection, Sensor, StepReport, N_ERR, STATE_WORDS,
};
pub use geodesy::LocalFrame;
pub use params::{AnalogFilter, Earth, EstimatorParams, Prediction, ProcessNoise, SensorNoise, Tuning};
