//! Plane geometry for localization: convex hull and area moments of polygons.

use nalgebra::Point2;

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
pub fn convex_hull(points: &[Point2<f64>]) -> Vec<Point2<f64>> {
    let mut p: Vec<Point2<f64>> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for q in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(*q);
        }
        hull.pop();
    }
    hull
}

/// Area moments `m_pq = integral over S of x^p y^q da` for p + q <= 2 of a simple polygon
/// (eq. (9) of the corner paper), summed over the triangles the polygon makes with the origin.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Moments {
    /// m00: area.
    pub m00: f64,
    /// m10.
    pub m10: f64,
    /// m01.
    pub m01: f64,
    /// m20.
    pub m20: f64,
    /// m11.
    pub m11: f64,
    /// m02.
    pub m02: f64,
}

impl Moments {
    /// The moments of the polygon with vertices `v` (either orientation; the area is positive).
    pub fn of_polygon(v: &[Point2<f64>]) -> Self {
        let mut m = Moments::default();
        let n = v.len();
        for i in 0..n {
            let (a, b) = (v[i], v[(i + 1) % n]);
            let c = a.x * b.y - b.x * a.y;
            m.m00 += c / 2.0;
            m.m10 += c * (a.x + b.x) / 6.0;
            m.m01 += c * (a.y + b.y) / 6.0;
            m.m20 += c * (a.x * a.x + a.x * b.x + b.x * b.x) / 12.0;
            m.m02 += c * (a.y * a.y + a.y * b.y + b.y * b.y) / 12.0;
            m.m11 += c * (2.0 * a.x * a.y + a.x * b.y + b.x * a.y + 2.0 * b.x * b.y) / 24.0;
        }
        if m.m00 < 0.0 {
            m = Moments {
                m00: -m.m00,
                m10: -m.m10,
                m01: -m.m01,
                m20: -m.m20,
                m11: -m.m11,
                m02: -m.m02,
            };
        }
        m
    }

    /// Centre of gravity, eq. (10).
    pub fn centroid(&self) -> Point2<f64> {
        Point2::new(self.m10 / self.m00, self.m01 / self.m00)
    }

    /// Direction of the principal axis with the smaller second moment (the long axis),
    /// eqs. (11)-(12), in (-pi/2, pi/2].
    pub fn long_axis(&self) -> f64 {
        let g = self.centroid();
        let mu20 = self.m20 - g.x * g.x * self.m00;
        let mu02 = self.m02 - g.y * g.y * self.m00;
        let mu11 = self.m11 - g.x * g.y * self.m00;
        let psi1 = 0.5 * (2.0 * mu11).atan2(mu20 - mu02);
        // Second moments about the axes at psi1 and psi1 + pi/2.
        let (s, c) = psi1.sin_cos();
        let i1 = mu20 * s * s - 2.0 * mu11 * s * c + mu02 * c * c;
        let i2 = mu20 * c * c + 2.0 * mu11 * s * c + mu02 * s * s;
        if i1 <= i2 {
            psi1
        } else {
            let p = psi1 + std::f64::consts::FRAC_PI_2;
            if p > std::f64::consts::FRAC_PI_2 {
                p - std::f64::consts::PI
            } else {
                p
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(cx: f64, cy: f64, hx: f64, hy: f64, angle: f64) -> Vec<Point2<f64>> {
        let (s, c) = angle.sin_cos();
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|(a, b)| {
                let (x, y) = (a * hx, b * hy);
                Point2::new(cx + c * x - s * y, cy + s * x + c * y)
            })
            .collect()
    }

    #[test]
    fn moments_of_a_rectangle() {
        let m = Moments::of_polygon(&rect(0.0, 0.0, 2.0, 1.0, 0.0));
        assert!((m.m00 - 8.0).abs() < 1e-12);
        assert!(m.m10.abs() < 1e-12 && m.m01.abs() < 1e-12);
        // Integral of x^2 over [-2,2]x[-1,1] = (2 * 2^3 / 3) * 2.
        assert!((m.m20 - 32.0 / 3.0).abs() < 1e-12);
        assert!((m.m02 - 8.0 / 3.0).abs() < 1e-12);
        assert!(m.m11.abs() < 1e-12);
    }

    #[test]
    fn centroid_and_long_axis_of_a_moved_turned_rectangle() {
        for angle in [0.0f64, 0.3, -1.2, 1.5] {
            let poly = rect(100.0, -50.0, 1370.0, 762.5, angle);
            let m = Moments::of_polygon(&poly);
            let g = m.centroid();
            assert!((g.x - 100.0).abs() < 1e-9 && (g.y + 50.0).abs() < 1e-9);
            let psi = m.long_axis();
            let d = (psi - angle).rem_euclid(std::f64::consts::PI);
            assert!(
                d < 1e-9 || (std::f64::consts::PI - d) < 1e-9,
                "{angle}: {psi}"
            );
            // Reversed orientation gives the same moments.
            let mut rev = poly.clone();
            rev.reverse();
            assert!((Moments::of_polygon(&rev).m00 - m.m00).abs() < 1e-6);
        }
        // A triangle: centroid at the mean of its vertices.
        let t = [
            Point2::new(0.0, 0.0),
            Point2::new(3.0, 0.0),
            Point2::new(0.0, 3.0),
        ];
        let g = Moments::of_polygon(&t).centroid();
        assert!((g.x - 1.0).abs() < 1e-12 && (g.y - 1.0).abs() < 1e-12);
    }

    #[test]
    fn hull_drops_interior_and_collinear_points() {
        let pts = vec![
            Point2::new(0.0, 0.0),
            Point2::new(2.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(2.0, 2.0),
            Point2::new(0.0, 2.0),
            Point2::new(1.0, 1.0),
        ];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4);
        assert!((Moments::of_polygon(&h).m00 - 4.0).abs() < 1e-12);
    }
}
