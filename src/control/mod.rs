//! Closed loop along a design: catflip's fixed-step plant with
//! delay, noise and model error ([`plant`], [`closed_loop`]), the nominal a
//! controller tracks ([`reference`](mod@reference)), the time-varying LQR ([`tvlqr`]) and
//! the Monte Carlo study of `catflip robustness` ([`robustness`]) and one
//! of its trials flown again ([`replay`]).

pub mod closed_loop;
pub mod export;
pub mod figure;
pub mod online;
pub mod plant;
pub mod reference;
pub mod replanning;
pub mod replay;
pub mod resume;
pub mod rng;
pub mod robustness;
pub mod tvlqr;
