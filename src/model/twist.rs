//! The twist law of the zero-momentum cat (docs/model.md F1, F6): how much
//! the body turns per turn of the bend direction at a given angle between
//! the halves. Pure physics, used by the closed forms, the phased design's
//! bend scan and the config's checks.

/// `I_yy = I_t cos^2(theta/2) + I_a sin^2(theta/2)` and
/// `C = 1 - (I_a / I_yy) sin(theta/2)` (F1) for the angle `theta` between the halves.
pub fn yy_inertia_and_c(i_t: f64, i_a: f64, theta: f64) -> (f64, f64) {
    let (s, c) = (theta / 2.0).sin_cos();
    let i_yy = i_t * c * c + i_a * s * s;
    (i_yy, 1.0 - i_a / i_yy * s)
}

/// The angle between the halves at which `n` full twists flip the cat by pi,
/// i.e. `C = 1/(2n)` (F6; erratum E6). With `k = 1 - 1/(2n)` and
/// `s = sin(theta/2)`: `k (I_t - I_a) s^2 + I_a s - k I_t = 0`, positive root.
pub fn turns_theta(i_t: f64, i_a: f64, turns: f64) -> f64 {
    let k = 1.0 - 1.0 / (2.0 * turns);
    let a = k * (i_t - i_a);
    let s = (-i_a + (i_a * i_a + 4.0 * a * k * i_t).sqrt()) / (2.0 * a);
    2.0 * s.clamp(-1.0, 1.0).asin()
}
