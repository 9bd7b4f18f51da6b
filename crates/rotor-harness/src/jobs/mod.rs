//! Front-end jobs shared by the command line and the Python package: a user's request,
//! checked in one place, and sweeps over a parameter plane (run, sharded, merged).

#![warn(missing_docs)]

pub mod request;
pub mod sweep;
