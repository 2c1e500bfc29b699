//! GI-Cube block processor units (patent [25]-[29], [346]-[392]).

pub mod bucket;
pub mod packet;
pub mod scatter;
pub mod sorter;
