//! The one boundary between the workspace's nalgebra 0.35 types and the glam
//! types (via `glamx`) that parry3d-f64 0.31 speaks. Everything else in this
//! room stores nalgebra types and converts here, right before a parry call.

use nalgebra::{Isometry3, Point3, Vector3};
use parry3d_f64::math::{Pose, Rotation, Vector};

/// nalgebra vector → glam `DVec3`.
#[inline]
pub(crate) fn vec_to_parry(v: &Vector3<f64>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// glam `DVec3` → nalgebra point.
#[inline]
pub(crate) fn point_from_parry(v: Vector) -> Point3<f64> {
    Point3::new(v.x, v.y, v.z)
}

/// nalgebra rigid transform → parry pose (same quaternion, same translation).
#[inline]
pub(crate) fn pose_to_parry(p: &Isometry3<f64>) -> Pose {
    let q = p.rotation.quaternion().coords; // (i, j, k, w)
    Pose::from_parts(
        vec_to_parry(&p.translation.vector),
        Rotation::from_xyzw(q.x, q.y, q.z, q.w),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn a_pose_maps_points_the_same_way_on_both_sides() {
        let p = Isometry3::from_parts(
            Translation3::new(0.3, -0.2, 1.1),
            UnitQuaternion::from_euler_angles(0.4, -1.2, 2.5),
        );
        let x = Point3::new(0.7, 0.1, -0.5);
        let ours = p * x;
        let theirs = pose_to_parry(&p) * Vector::new(x.x, x.y, x.z);
        assert!((point_from_parry(theirs) - ours).norm() < 1e-12);
    }
}
