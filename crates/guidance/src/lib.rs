//! Guidance laws shared by the tail-sitter controllers, built on the mission definition
//! of [`flight_mission`]: the α- and thrust-limited flight-path profile of the
//! transitions ([`profile`]), the weathervane heading reference ([`weathervane`]) and the
//! take-off and landing phases around the mission ([`ground`]).

pub mod ground;
pub mod profile;
pub mod weathervane;
pub use ground::{GroundMode, GroundPhases, VerticalReference};
pub use profile::{PathPoint, PointMass, Profile, ProfileLimits};
pub use weathervane::{HeadingRef, Weathervane, WeathervaneParams};
