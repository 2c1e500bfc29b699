//! Studies built on the golden model, not part of it: the speed/accuracy tradeoff sweeps
//! (`cube5 tradeoff`, docs/tradeoffs.md). The golden model (`cube5-model`) does not depend on this
//! crate.

pub mod tradeoff;
