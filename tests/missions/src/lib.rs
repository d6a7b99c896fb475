//! Test-only crate: the controllers and the estimator flown through whole missions with
//! the closed-loop harness (`tests/`, `benches/`, `examples/`). It sits above every crate
//! it flies, so none of them depends, even for its tests, on a crate above it.
