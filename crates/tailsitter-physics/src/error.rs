//! Errors of the physics: non-finite values, envelope violations, failed trims.

use core::fmt;

use crate::airframe::InvalidParameter;

/// What went wrong in [`crate::Plant`]. `Display` names the offending state, input or
/// quantity, e.g. `airspeed 812 m/s exceeds envelope (200 m/s)` or `state u is NaN`.
/// Everything except [`PhysicsError::Trim`] is built without allocating.
#[derive(Debug, Clone, PartialEq)]
pub enum PhysicsError {
    /// A state became NaN or infinite.
    NonFiniteState {
        /// State name (see [`crate::idx::STATE_NAMES`]).
        state: &'static str,
        /// Its value.
        value: f64,
    },
    /// An input (command or wind) is NaN or infinite.
    NonFiniteInput {
        /// Input name (`thrust_cmd`, …, `wind_n`, …).
        input: &'static str,
        /// Its value.
        value: f64,
    },
    /// A quantity left the sane envelope of the model.
    Envelope {
        /// Quantity (`airspeed`, `speed`, `p`, `pos_n`, …).
        quantity: &'static str,
        /// Its value.
        value: f64,
        /// The limit it exceeded (magnitude).
        limit: f64,
        /// Unit of value and limit.
        unit: &'static str,
    },
    /// A bad argument (step size, integration step, trim speed).
    InvalidArgument {
        /// The argument.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// The airframe parameters are invalid.
    Airframe(InvalidParameter),
    /// A trim did not converge or needs more than the actuators can give.
    Trim(String),
}

impl fmt::Display for PhysicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteState { state, value } => write!(f, "state {state} is {}", nonfinite(*value)),
            Self::NonFiniteInput { input, value } => write!(f, "input {input} is {}", nonfinite(*value)),
            Self::Envelope {
                quantity,
                value,
                limit,
                unit,
            } => {
                write!(f, "{quantity} {value:.6} {unit} exceeds envelope ({limit} {unit})")
            }
            Self::InvalidArgument {
                name,
                value,
                requirement,
            } => write!(f, "{name} = {value} must be {requirement}"),
            Self::Airframe(p) => write!(f, "invalid airframe: {p}"),
            Self::Trim(msg) => write!(f, "trim failed: {msg}"),
        }
    }
}

fn nonfinite(v: f64) -> &'static str {
    if v.is_nan() {
        "NaN"
    } else if v > 0.0 {
        "+infinite"
    } else if v < 0.0 {
        "-infinite"
    } else {
        "finite"
    }
}

impl std::error::Error for PhysicsError {}

impl From<InvalidParameter> for PhysicsError {
    fn from(p: InvalidParameter) -> Self {
        Self::Airframe(p)
    }
}
