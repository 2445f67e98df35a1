//! Checks of settings and angle arithmetic shared by the omnistereo modules.

use crate::VisionError;

pub(crate) use crate::positive;

/// `value` must be below `limit` (`rule` says so in words).
pub(crate) fn below(
    name: &'static str,
    value: f64,
    limit: f64,
    rule: &'static str,
) -> Result<(), VisionError> {
    if value < limit {
        Ok(())
    } else {
        Err(VisionError::InvalidParameter { name, value, rule })
    }
}

/// Wraps an angle into (-pi, pi].
pub(crate) fn wrap(a: f64) -> f64 {
    use std::f64::consts::PI;
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI { w + 2.0 * PI } else { w }
}
