//! A ray, and the reflection and quadratic that every mirror's intersection uses.

use nalgebra::{Point3, Vector3};

/// A ray: origin and unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Point3<f64>,
    /// Unit direction.
    pub dir: Vector3<f64>,
    /// How far light travels from the camera's viewpoint (its lens centre) to `origin`, mm:
    /// the camera ray to the mirror (0 where the ray starts at the lens, a pinhole's).
    pub path_mm: f64,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> Point3<f64> {
        self.origin + self.dir * t
    }

    /// Where the ray meets the floor `z = 0`, if it goes down.
    pub fn floor_hit(&self) -> Option<Point3<f64>> {
        (self.dir.z < 0.0).then(|| self.at(-self.origin.z / self.dir.z))
    }
}

/// Mirror reflection: `d - 2 (d . n) n` for a unit normal `n`.
pub fn reflect(d: Vector3<f64>, n: Vector3<f64>) -> Vector3<f64> {
    d - n * (2.0 * d.dot(&n))
}

/// The roots of `a t^2 + b t + c = 0` in increasing order, computed without cancellation.
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a.abs() < 1e-300 {
        if b.abs() < 1e-300 {
            return None;
        }
        let t = -c / b;
        return Some((t, t));
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_ordered_and_accurate() {
        let (a, b) = solve_quadratic(1.0, -3.0, 2.0).unwrap();
        assert!((a - 1.0).abs() < 1e-15 && (b - 2.0).abs() < 1e-15);
        // Large b: the naive formula loses the small root.
        let (a, _) = solve_quadratic(1.0, -1e8, 1.0).unwrap();
        assert!((a - 1e-8).abs() < 1e-20);
        assert!(solve_quadratic(1.0, 0.0, 1.0).is_none());
    }

    #[test]
    fn reflection_preserves_length_and_flips_the_normal_component() {
        let n = Vector3::new(0.0, 0.0, 1.0);
        let r = reflect(Vector3::new(0.6, 0.0, -0.8), n);
        assert!((r - Vector3::new(0.6, 0.0, 0.8)).norm() < 1e-15);
    }
}
