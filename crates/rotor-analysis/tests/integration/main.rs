//! rotor_analysis::bifurcation's integration tests, in one test binary so that the two default
//! diagrams (`common`) are computed once for all the modules that check them.

mod common;
mod diagram;
mod floquet;
mod lyapunov;
mod output;
mod points;
mod variational;
