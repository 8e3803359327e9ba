//! nalgebra ↔ proto conversions. Quaternions travel as named x, y, z, w fields
//! (w the scalar part), so no component order can be mixed up.

use nalgebra::{DMatrix, DVector, Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::error::{Error, Result};
use crate::pb;

/// A pose as the proto carries it.
pub fn pose_to_proto(pose: &Isometry3<f64>) -> pb::Pose {
    let p = pose.translation.vector;
    let q = pose.rotation.quaternion();
    pb::Pose {
        position: Some(vec3_to_proto(&p)),
        orientation: Some(pb::Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }),
    }
}

pub fn vec3_to_proto(v: &Vector3<f64>) -> pb::Vec3 {
    pb::Vec3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

/// A proto pose; `what` names the reply field when it is missing. An unset
/// (all-zero) quaternion is the identity, as the contract says.
pub fn pose_from_proto(pose: Option<&pb::Pose>, what: &'static str) -> Result<Isometry3<f64>> {
    let pose = pose.ok_or(Error::Reply(what))?;
    let p = pose.position.unwrap_or_default();
    let q = pose.orientation.unwrap_or_default();
    let rotation = if [q.x, q.y, q.z, q.w] == [0.0; 4] {
        UnitQuaternion::identity()
    } else {
        UnitQuaternion::new_normalize(Quaternion::new(q.w, q.x, q.y, q.z))
    };
    Ok(Isometry3::from_parts(Translation3::new(p.x, p.y, p.z), rotation))
}

/// A row-major proto matrix as a dense matrix, checking that the data fit.
pub fn matrix_from_proto(m: Option<&pb::Matrix>, what: &'static str) -> Result<DMatrix<f64>> {
    let m = m.ok_or(Error::Reply(what))?;
    let (rows, cols) = (m.rows as usize, m.cols as usize);
    if rows.checked_mul(cols) != Some(m.data.len()) {
        return Err(Error::Reply(what));
    }
    Ok(DMatrix::from_row_slice(rows, cols, &m.data))
}

/// Rows of joint states (n × dof) as a row-major proto matrix.
pub fn states_to_proto(states: &[DVector<f64>]) -> pb::Matrix {
    let cols = states.first().map_or(0, |s| s.len());
    pb::Matrix {
        rows: states.len() as u32,
        cols: cols as u32,
        data: states.iter().flat_map(|s| s.iter().copied()).collect(),
    }
}
