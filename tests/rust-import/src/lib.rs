//! Integration tests that load the packaged FMUs from `dist/` through the `fmi`
//! crate, an importer independent of our export layer. Build the FMUs first
//! (`cargo xtask dist`); the tests fail with that hint when they are missing.
