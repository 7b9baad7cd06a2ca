//! Design: the torque schedules. The seed's closed-form schedule, the
//! certified phased optimum (path-timing SOCPs) and the free-form optimum
//! (collocation + successive convexification), with the shape plans and
//! sampled schedules they produce and the conic solver they share.
pub mod analytic;
pub mod bend_search;
pub mod collocation;
pub mod collocation_plan;
pub mod conic;
pub mod envelope;
pub mod free;
pub mod least_height;
pub mod mirror;
pub mod objective;
pub mod path;
pub mod phased;
pub mod plan;
pub mod release;
pub mod scp;
pub mod spec;
pub mod timing;
pub mod twist;
