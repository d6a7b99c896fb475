//! `tailsitter_tsd`: the time-scale-decoupled controller of thesis chapter 4 as
//! an FMI 2.0 Co-Simulation FMU. Not built yet (issue "TSD controller FMU"); this
//! crate reserves its place in the workspace layout and exports nothing.
