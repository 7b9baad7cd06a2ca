//! Verification: forward simulation of a schedule in the full free-floating
//! model (adaptive ODE integration), and the analysis of the seed's schedule.
pub mod analyze;
pub mod ode;
pub mod simulate;
