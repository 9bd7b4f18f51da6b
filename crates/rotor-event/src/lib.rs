//! Event-driven Filippov solver for the rotor (Piiroinen & Kuznetsov, ACM TOMS 34(3), 2008).
pub mod dop853;
pub mod tableau;
