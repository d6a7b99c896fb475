//! `tailsitter_lqr`: the gain-scheduled LQR controller of thesis chapter 3 as an
//! FMI 2.0 Co-Simulation FMU. Not built yet (issue "LQR controller FMU"); this
//! crate reserves its place in the workspace layout and exports nothing.
