//! Leine's switch-model solver for the two-disc rotor (see `../shared/METHODS.md` §1.1).

pub mod dopri5;
