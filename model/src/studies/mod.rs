//! Studies built on the golden model, not part of it: the speed/accuracy tradeoff sweeps
//! (`cube5 tradeoff`, docs/tradeoffs.md). Nothing under `units` depends on this module.

pub mod tradeoff;
