//! A closed-form shape around the points of a convex hull (a robot mesh
//! used as its hull), so that most queries on the hull are answered by the
//! closed forms of `fast`: the bound apart from something proves the hull
//! apart from it; only where the bound meets something does the exact hull
//! test run.
//!
//! Candidates, the least volume kept: a capsule along each principal axis
//! of the points (the eigenvectors of their covariance) and the box over
//! the principal axes. For a capsule of axis `u`: the points are projected
//! across `u`, a centre `c` of a small circle around them is found by
//! Bădoiu and Clarkson's iteration (`c ← c + (p_far − c)/(k + 2)`, `k =
//! 0..64`, from the centre of their bounding rectangle; "Smaller core-sets
//! for balls", SODA 2003), `r₀` is the largest distance from `c`, and for
//! each radius `r = f·r₀`, `f ∈ {1, 1.1, 1.25, 1.5}`, the segment on the
//! axis is as short as the points allow: a point at axial coordinate `tᵢ`
//! and distance `dᵢ ≤ r` from the axis lies in the capsule when the segment
//! reaches `[tᵢ − hᵢ, tᵢ + hᵢ]`, `hᵢ = √(r² − dᵢ²)`, so the segment
//! `[minᵢ(tᵢ + hᵢ), maxᵢ(tᵢ − hᵢ)]` (its midpoint when empty) holds every
//! point. Every size is grown by `SLACK` for rounding. Linear in the point
//! count.

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::fast::RobotFast;

/// Added to every radius and half extent (m), for the rounding of the fit.
const SLACK: f64 = 1e-9;
const CENTRE_STEPS: usize = 64;
const RADIUS_FACTORS: [f64; 4] = [1.0, 1.1, 1.25, 1.5];

/// The least-volume candidate of the module doc around `points` (a shape's
/// frame); `RobotFast::None` when there are none or they are not finite.
pub(crate) fn enclosing(points: &[Point3<f64>]) -> RobotFast {
    if points.is_empty() || !points.iter().all(|p| p.coords.iter().all(|x| x.is_finite())) {
        return RobotFast::None;
    }
    let n = points.len() as f64;
    let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let cov = points.iter().fold(Matrix3::zeros(), |s, p| {
        let d = p.coords - mean;
        s + d * d.transpose()
    });
    let axes = principal_axes(&cov);
    let mut best = box_over(points, &axes);
    for k in 0..3 {
        let capsule = capsule_along(points, &axes.column(k).into_owned());
        if capsule.0 < best.0 {
            best = capsule;
        }
    }
    best.1
}

/// A right-handed orthonormal frame of eigenvectors of `cov` (the identity
/// when the decomposition is not finite).
fn principal_axes(cov: &Matrix3<f64>) -> Matrix3<f64> {
    let eig = cov.symmetric_eigen();
    let mut m = eig.eigenvectors;
    if !m.iter().all(|x| x.is_finite()) {
        return Matrix3::identity();
    }
    let (x, y) = (m.column(0).normalize(), m.column(1).into_owned());
    let y = (y - x * x.dot(&y)).normalize();
    let z = x.cross(&y);
    if !(x.iter().chain(y.iter()).chain(z.iter()).all(|v| v.is_finite())) {
        return Matrix3::identity();
    }
    m.set_column(0, &x);
    m.set_column(1, &y);
    m.set_column(2, &z);
    m
}

/// (volume, box) over `points` in the frame whose axes are `axes`' columns.
fn box_over(points: &[Point3<f64>], axes: &Matrix3<f64>) -> (f64, RobotFast) {
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for p in points {
        let local = axes.transpose() * p.coords;
        lo = lo.inf(&local);
        hi = hi.sup(&local);
    }
    let half = (0.5 * (hi - lo)).add_scalar(SLACK);
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*axes));
    let offset = Isometry3::from_parts(Translation3::from(axes * (0.5 * (lo + hi))), rotation);
    (8.0 * half.x * half.y * half.z, RobotFast::Box { offset, half })
}

/// (volume, capsule) of axis `u` around `points` (module doc).
fn capsule_along(points: &[Point3<f64>], u: &Vector3<f64>) -> (f64, RobotFast) {
    let u = u.normalize();
    let a = u
        .cross(&if u.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        })
        .normalize();
    let b = u.cross(&a);
    let across = |p: &Point3<f64>| Vector2::new(p.coords.dot(&a), p.coords.dot(&b));
    let (mut lo, mut hi) = (Vector2::repeat(f64::INFINITY), Vector2::repeat(f64::NEG_INFINITY));
    for p in points {
        lo = lo.inf(&across(p));
        hi = hi.sup(&across(p));
    }
    let mut c = 0.5 * (lo + hi);
    let farthest = |c: &Vector2<f64>| {
        points
            .iter()
            .map(&across)
            .max_by(|x, y| (x - c).norm_squared().total_cmp(&(y - c).norm_squared()))
            .expect("points")
    };
    for k in 0..CENTRE_STEPS {
        let far = farthest(&c);
        c += (far - c) / (k as f64 + 2.0);
    }
    let r0 = (farthest(&c) - c).norm();
    let base = c.x * a + c.y * b;
    let mut best = (f64::INFINITY, RobotFast::None);
    for f in RADIUS_FACTORS {
        let r = r0 * f;
        // the segment must start at or below every tᵢ + hᵢ and end at or above every tᵢ − hᵢ
        let (mut start, mut end) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in points {
            let d2 = (across(p) - c).norm_squared();
            let h = (r * r - d2).max(0.0).sqrt();
            let t = p.coords.dot(&u);
            start = start.min(t + h);
            end = end.max(t - h);
        }
        let (t0, t1) = if start <= end {
            (start, end)
        } else {
            (0.5 * (start + end), 0.5 * (start + end))
        };
        let r = r + SLACK;
        let volume = std::f64::consts::PI * r * r * (t1 - t0 + 4.0 / 3.0 * r);
        if volume < best.0 {
            best = (
                volume,
                RobotFast::Swept {
                    a: Point3::from(base + t0 * u),
                    b: Point3::from(base + t1 * u),
                    r,
                },
            );
        }
    }
    best
}

#[cfg(test)]
pub(crate) mod tests {
    use nalgebra::{Point3, Rotation3, Vector3};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::{RobotFast, enclosing};

    /// How far `p` lies outside the closed form (≤ 0: inside), by the
    /// definitions: distance to the segment less the radius, or the box's
    /// local coordinates against its half extents.
    pub(crate) fn outside(shape: &RobotFast, p: &Point3<f64>) -> f64 {
        match *shape {
            RobotFast::Swept { a, b, r } => {
                let ab = b - a;
                let t = if ab.norm_squared() > 0.0 {
                    ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (p - (a + ab * t)).norm() - r
            }
            RobotFast::Box { offset, half } => {
                let local = offset.inverse_transform_point(p);
                (local.coords.abs() - half).max()
            }
            RobotFast::None => f64::INFINITY,
        }
    }

    #[test]
    fn the_bound_holds_every_point_of_long_flat_and_degenerate_clouds() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let clouds: Vec<Vec<Point3<f64>>> = vec![
            vec![Point3::new(0.3, -0.2, 0.1)],
            (0..20)
                .map(|i| Point3::new(0.01 * i as f64, 0.02 * i as f64, -0.03 * i as f64))
                .collect(),
            (0..200)
                .map(|_| {
                    Point3::new(
                        rng.random_range(-0.4..0.4),
                        rng.random_range(-0.05..0.05),
                        rng.random_range(-0.05..0.05),
                    )
                })
                .collect(),
            (0..200)
                .map(|_| Point3::new(rng.random_range(-0.2..0.2), rng.random_range(-0.2..0.2), 0.0))
                .collect(),
        ];
        for (k, cloud) in clouds.iter().enumerate() {
            let turn = Rotation3::from_scaled_axis(Vector3::new(0.3, -1.1, 0.7));
            let cloud: Vec<Point3<f64>> = cloud
                .iter()
                .map(|p| turn * p + Vector3::new(1.0, 2.0, -0.5))
                .collect();
            let bound = enclosing(&cloud);
            assert!(!matches!(bound, RobotFast::None), "cloud {k}");
            for p in &cloud {
                assert!(outside(&bound, p) <= 0.0, "cloud {k}: {p:?} outside {bound:?}");
            }
        }
        // a long thin rod gets a capsule no wider than the rod's corners need
        let rod: Vec<Point3<f64>> = [-0.5, 0.5]
            .iter()
            .flat_map(|&x| {
                [(-0.02, -0.02), (-0.02, 0.02), (0.02, -0.02), (0.02, 0.02)]
                    .map(|(y, z)| Point3::new(x, y, z))
            })
            .collect();
        match enclosing(&rod) {
            RobotFast::Swept { r, .. } => assert!(r < 0.03, "{r}"),
            RobotFast::Box { half, .. } => assert!(half.min() < 0.021, "{half}"),
            RobotFast::None => panic!("no bound"),
        }
        assert!(matches!(enclosing(&[]), RobotFast::None));
        assert!(matches!(
            enclosing(&[Point3::new(f64::NAN, 0.0, 0.0)]),
            RobotFast::None
        ));
    }
}
