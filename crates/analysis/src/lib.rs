//! Analysis of the tail-sitter controllers of S.C. Kriel's thesis: open-loop modes
//! (§3.4.2, Tables 3.2/3.3), closed-loop poles by the Jacobian of the closed-loop sampled
//! map (§3.4.2 Figs. 3.16/3.17, §4.4.1 Tables 4.3/4.4), the sensitivity study of §5.1
//! (Table 5.1, Figs. 5.1/5.2) and, beyond the thesis, nonlinear robustness sweeps
//! (parameter scaling and 1−cos gusts flown through the whole mission).
//!
//! See README.md for the command that regenerates everything.

pub mod aero_models;
pub mod cache;
pub mod closed;
pub mod controllers;
pub mod envelope_hover;
pub mod envelope_transitions;
pub mod linalg;
pub mod modes;
pub mod native_campaign;
pub mod reproduction;
pub mod reproduction_flights;
pub mod robust;
pub mod sensitivity;
pub mod sweep;
pub mod takeoff_landing;
pub mod transition_bound;
pub mod wind_envelope;
