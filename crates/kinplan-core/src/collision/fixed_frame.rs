//! The fixed transforms of a chain (joint origins, body offsets), applied
//! by forward kinematics with only the arithmetic their shape needs.
//!
//! URDF origins are mostly a shift along one axis and a turn about one
//! axis (the Panda's are `rpy = (±π/2, 0, 0)` with `xyz` along a single
//! axis). For a frame `t = (p, q)` (unit quaternion `q = (w, i, j, k)`) and
//! a fixed transform `(d, r)`, `t · (d, r) = (p + q·d, q·r)`, and:
//!
//! * `q·d` for `d = δ·e_a` is `δ` times column `a` of `q`'s rotation matrix,
//!   e.g. column z = `(2(ik + wj), 2(jk − wi), 1 − 2(i² + j²))`, instead of
//!   the general quaternion rotation;
//! * `q·r` for `r = (c, s·e_a)`, a turn about axis `a`, is four products
//!   pairs (written out in [`turned`]) instead of the Hamilton product.
//!
//! Components below [`NEGLIGIBLE`] count as zero (URDF exporters leave
//! `1e-17`-sized residues of `cos(π/2)`).

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// Components this small (m, or of a unit quaternion) are treated as zero.
const NEGLIGIBLE: f64 = 1e-15;

/// A fixed rigid transform, shaped for [`FixedFrame::after`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FixedFrame {
    shift: Shift,
    turn: Turn,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Shift {
    None,
    /// `δ` along axis `a` (0 = x, 1 = y, 2 = z).
    Along(usize, f64),
    General(Vector3<f64>),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Turn {
    None,
    /// The quaternion `(c, s·e_a)`: a turn about axis `a`.
    About(usize, f64, f64),
    General(UnitQuaternion<f64>),
}

impl FixedFrame {
    pub fn of(t: &Isometry3<f64>) -> Self {
        let d = t.translation.vector;
        let nonzero: Vec<usize> = (0..3).filter(|&a| d[a].abs() > NEGLIGIBLE).collect();
        let shift = match nonzero[..] {
            [] => Shift::None,
            [a] => Shift::Along(a, d[a]),
            _ => Shift::General(d),
        };
        let q = t.rotation.quaternion();
        let v = [q.i, q.j, q.k];
        let turning: Vec<usize> = (0..3).filter(|&a| v[a].abs() > NEGLIGIBLE).collect();
        let turn = match turning[..] {
            [] if q.w > 0.0 => Turn::None,
            [] => Turn::About(2, q.w, 0.0), // the identity as −1: a sign kept
            [a] => Turn::About(a, q.w, v[a]),
            _ => Turn::General(t.rotation),
        };
        FixedFrame { shift, turn }
    }

    /// True when applying it changes nothing.
    pub fn is_identity(&self) -> bool {
        self.shift == Shift::None && self.turn == Turn::None
    }

    /// `t · self`.
    #[inline]
    pub fn after(&self, t: &Isometry3<f64>) -> Isometry3<f64> {
        let shift = match self.shift {
            Shift::None => Vector3::zeros(),
            Shift::Along(a, d) => column(&t.rotation, a) * d,
            Shift::General(d) => t.rotation * d,
        };
        let rotation = match self.turn {
            Turn::None => t.rotation,
            Turn::About(a, c, s) => turned(&t.rotation, a, c, s),
            Turn::General(r) => t.rotation * r,
        };
        Isometry3::from_parts(Translation3::from(t.translation.vector + shift), rotation)
    }
}

/// Column `a` of the rotation matrix of the unit quaternion `q`: where `q`
/// takes the unit vector `e_a`.
#[inline]
pub(crate) fn column(q: &UnitQuaternion<f64>, a: usize) -> Vector3<f64> {
    let q = q.quaternion();
    let (w, i, j, k) = (q.w, q.i, q.j, q.k);
    match a {
        0 => Vector3::new(
            1.0 - 2.0 * (j * j + k * k),
            2.0 * (i * j + w * k),
            2.0 * (i * k - w * j),
        ),
        1 => Vector3::new(
            2.0 * (i * j - w * k),
            1.0 - 2.0 * (i * i + k * k),
            2.0 * (j * k + w * i),
        ),
        _ => Vector3::new(
            2.0 * (i * k + w * j),
            2.0 * (j * k - w * i),
            1.0 - 2.0 * (i * i + j * j),
        ),
    }
}

/// `q · (c, s·e_a)` (Hamilton product with a turn about axis `a`) written out.
#[inline]
pub(crate) fn turned(q: &UnitQuaternion<f64>, a: usize, c: f64, s: f64) -> UnitQuaternion<f64> {
    let q = q.quaternion();
    let (w, i, j, k) = (q.w, q.i, q.j, q.k);
    let (w, i, j, k) = match a {
        0 => (w * c - i * s, i * c + w * s, j * c + k * s, k * c - j * s),
        1 => (w * c - j * s, i * c - k * s, j * c + w * s, k * c + i * s),
        _ => (w * c - k * s, i * c + j * s, j * c - i * s, k * c + w * s),
    };
    UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_frame(rng: &mut ChaCha8Rng) -> Isometry3<f64> {
        let axis = Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 1.0);
        Isometry3::from_parts(
            Translation3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.3),
            UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                rng.random_range(-3.0..3.0),
            ),
        )
    }

    #[test]
    fn every_shape_of_fixed_transform_composes_as_the_isometry_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let quarter = std::f64::consts::FRAC_PI_2;
        let mut fixed = vec![
            Isometry3::identity(),
            Isometry3::translation(0.0, 0.0, 0.333),
            Isometry3::translation(0.0, -0.316, 1.9e-17), // a URDF residue
            Isometry3::translation(-0.0825, 0.384, 0.0),
            Isometry3::rotation(Vector3::new(0.0, 0.0, std::f64::consts::PI)), // w = 0
            Isometry3::rotation(Vector3::new(0.0, 0.0, 2.0 * std::f64::consts::PI)), // w = −1
        ];
        for a in 0..3 {
            for angle in [quarter, -quarter, 0.3, -2.0] {
                let mut axis = Vector3::zeros();
                axis[a] = angle;
                fixed.push(Isometry3::new(Vector3::new(0.1, 0.0, 0.0), axis));
                fixed.push(Isometry3::rotation(axis));
            }
        }
        fixed.push(random_frame(&mut rng));
        for f in &fixed {
            let shaped = FixedFrame::of(f);
            for _ in 0..20 {
                let t = random_frame(&mut rng);
                let (ours, theirs) = (shaped.after(&t), t * f);
                let moved = (ours.translation.vector - theirs.translation.vector).norm();
                // same rotation: the quaternions agree up to sign
                let turned = ours.rotation.angle_to(&theirs.rotation);
                assert!(
                    moved < 1e-14 && turned < 1e-7,
                    "{f:?}: {moved:e} m, {turned:e} rad"
                );
                let p = Vector3::new(0.3, -0.2, 0.5);
                let gap = (ours.rotation * p - theirs.rotation * p).norm();
                assert!(gap < 1e-14, "{f:?}: {gap:e}");
            }
        }
        assert!(FixedFrame::of(&Isometry3::identity()).is_identity());
        assert!(!FixedFrame::of(&fixed[5]).is_identity());
    }

    #[test]
    fn columns_are_where_the_rotation_takes_the_unit_vectors() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100 {
            let q = random_frame(&mut rng).rotation;
            for a in 0..3 {
                let mut e = Vector3::zeros();
                e[a] = 1.0;
                assert!((column(&q, a) - q * e).norm() < 1e-14);
            }
        }
    }
}
