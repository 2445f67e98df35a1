//! Angles: wrapping into (-pi, pi] and the unsigned difference of two directions.

use std::f64::consts::{PI, TAU};

/// `a` wrapped into `(-pi, pi]`.
pub fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// The unsigned angle between directions `a` and `b`, in `[0, pi]`.
pub fn angle_diff(a: f64, b: f64) -> f64 {
    wrap_pi(a - b).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_into_the_half_open_interval() {
        assert!((wrap_pi(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(-PI) - PI).abs() < 1e-12, "-pi maps to +pi");
        assert!((wrap_pi(TAU + 0.5) - 0.5).abs() < 1e-12);
        assert!((wrap_pi(-0.5 - 2.0 * TAU) + 0.5).abs() < 1e-12);
        assert!((angle_diff(0.1, TAU - 0.1) - 0.2).abs() < 1e-12);
        assert!((angle_diff(-3.0, 3.0) - (TAU - 6.0)).abs() < 1e-12);
    }
}
