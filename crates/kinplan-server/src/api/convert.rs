//! Proto ↔ nalgebra conversions, validating every number on the way in.

use nalgebra::{DMatrix, Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use tonic::Status;

use crate::pb;
use crate::status::invalid;

/// Largest accepted deviation of a quaternion's norm from 1.
const UNIT_TOLERANCE: f64 = 1e-6;

pub fn finite(field: &str, value: f64) -> Result<f64, Status> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(invalid(field, format!("must be finite, got {value}")))
    }
}

/// An optional duration in seconds: unset is `None`; set, it must be finite and > 0.
pub fn optional_seconds(field: &str, value: Option<f64>) -> Result<Option<std::time::Duration>, Status> {
    value
        .map(|b| {
            std::time::Duration::try_from_secs_f64(b)
                .ok()
                .filter(|d| !d.is_zero())
                .ok_or_else(|| invalid(field, format!("must be finite and > 0 s, got {b}")))
        })
        .transpose()
}

pub fn finite_slice(field: &str, values: &[f64]) -> Result<(), Status> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(invalid(
            format!("{field}[{i}]"),
            format!("must be finite, got {}", values[i]),
        )),
        None => Ok(()),
    }
}

pub fn vec3_in(field: &str, v: Option<&pb::Vec3>) -> Result<Vector3<f64>, Status> {
    vec3_at(&|| field.to_owned(), v)
}

/// [`vec3_in`] with the field's name made by `field` only when a value is
/// refused: the conversions of a request's many poses and shapes format no
/// text on success.
pub fn vec3_at(field: &dyn Fn() -> String, v: Option<&pb::Vec3>) -> Result<Vector3<f64>, Status> {
    let v = v.cloned().unwrap_or_default();
    for (name, value) in [("x", v.x), ("y", v.y), ("z", v.z)] {
        if !value.is_finite() {
            finite(&format!("{}.{name}", field()), value)?;
        }
    }
    Ok(Vector3::new(v.x, v.y, v.z))
}

/// An unset (all-zero) quaternion is the identity; otherwise it must be unit.
pub fn quaternion_in(field: &str, q: Option<&pb::Quaternion>) -> Result<UnitQuaternion<f64>, Status> {
    quaternion_at(&|| field.to_owned(), q)
}

/// [`quaternion_in`], the field's name made only when the value is refused.
pub fn quaternion_at(
    field: &dyn Fn() -> String,
    q: Option<&pb::Quaternion>,
) -> Result<UnitQuaternion<f64>, Status> {
    let q = q.cloned().unwrap_or_default();
    for (name, value) in [("x", q.x), ("y", q.y), ("z", q.z), ("w", q.w)] {
        if !value.is_finite() {
            finite(&format!("{}.{name}", field()), value)?;
        }
    }
    let raw = Quaternion::new(q.w, q.x, q.y, q.z);
    if [q.w, q.x, q.y, q.z].iter().all(|c| *c == 0.0) {
        return Ok(UnitQuaternion::identity());
    }
    // The norm scaled by the largest component: a tiny quaternion such as
    // (0, 0, 0, 1e-200) has a tiny norm, not one that underflows to 0.
    let largest = [q.w, q.x, q.y, q.z].iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    let norm = largest * (raw / largest).norm();
    if (norm - 1.0).abs() > UNIT_TOLERANCE {
        return Err(invalid(
            field(),
            format!("quaternion must have norm 1 (within {UNIT_TOLERANCE}), got {norm}"),
        ));
    }
    Ok(UnitQuaternion::new_normalize(raw))
}

pub fn pose_in(field: &str, p: Option<&pb::Pose>) -> Result<Isometry3<f64>, Status> {
    pose_at(&|| field.to_owned(), p)
}

/// [`pose_in`], the field's name made only when a value is refused.
pub fn pose_at(field: &dyn Fn() -> String, p: Option<&pb::Pose>) -> Result<Isometry3<f64>, Status> {
    let Some(p) = p else {
        return Err(invalid(field(), "is required"));
    };
    let t = vec3_at(&|| format!("{}.position", field()), p.position.as_ref())?;
    let r = quaternion_at(&|| format!("{}.orientation", field()), p.orientation.as_ref())?;
    Ok(Isometry3::from_parts(Translation3::from(t), r))
}

pub fn vec3_out(v: &Vector3<f64>) -> pb::Vec3 {
    pb::Vec3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

pub fn pose_out(t: &Isometry3<f64>) -> pb::Pose {
    let q = t.rotation.quaternion();
    pb::Pose {
        position: Some(vec3_out(&t.translation.vector)),
        orientation: Some(pb::Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }),
    }
}

/// Row-major proto matrix from any nalgebra matrix.
pub fn matrix_out<R: nalgebra::Dim, C: nalgebra::Dim, S: nalgebra::RawStorage<f64, R, C>>(
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> pb::Matrix {
    let (rows, cols) = m.shape();
    let mut data = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            data.push(m[(r, c)]);
        }
    }
    pb::Matrix {
        rows: rows as u32,
        cols: cols as u32,
        data,
    }
}

/// A proto matrix checked for shape, size and finiteness.
pub fn matrix_in(field: &str, m: Option<&pb::Matrix>, max_entries: usize) -> Result<DMatrix<f64>, Status> {
    let Some(m) = m else {
        return Err(invalid(field, "is required"));
    };
    let (rows, cols) = (m.rows as usize, m.cols as usize);
    if rows == 0 || cols == 0 {
        return Err(invalid(field, format!("shape {rows}x{cols} is empty")));
    }
    let entries = rows.saturating_mul(cols);
    if entries > max_entries {
        return Err(invalid(
            field,
            format!("{entries} entries exceed the limit of {max_entries}"),
        ));
    }
    if m.data.len() != entries {
        return Err(invalid(
            format!("{field}.data"),
            format!("has {} values, shape {rows}x{cols} needs {entries}", m.data.len()),
        ));
    }
    finite_slice(&format!("{field}.data"), &m.data)?;
    Ok(DMatrix::from_row_slice(rows, cols, &m.data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip_and_identity_default() {
        let t = Isometry3::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.3, 0.2, -0.1));
        let back = pose_in("p", Some(&pose_out(&t))).unwrap();
        assert!((back.to_homogeneous() - t.to_homogeneous()).norm() < 1e-12);
        let unset = pb::Pose {
            position: None,
            orientation: None,
        };
        assert_eq!(pose_in("p", Some(&unset)).unwrap(), Isometry3::identity());
    }

    #[test]
    fn bad_numbers_name_their_field() {
        let q = pb::Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 2.0,
        };
        let err = quaternion_in("target.orientation", Some(&q)).unwrap_err();
        assert!(err.message().starts_with("target.orientation"));
        // Regression: tiny quaternions were read as the identity (their norm
        // underflowed to 0); only the all-zero one means "unset".
        for (x, w) in [(0.0, 1e-200), (1e-300, 0.0), (0.0, 1e-7)] {
            let q = pb::Quaternion { x, y: 0.0, z: 0.0, w };
            let err = quaternion_in("box.orientation", Some(&q)).unwrap_err();
            assert!(err.message().contains("norm 1"), "({x}, {w}): {}", err.message());
        }
        let unit = pb::Quaternion {
            x: 0.6,
            y: 0.0,
            z: 0.0,
            w: 0.8,
        };
        assert!(quaternion_in("q", Some(&unit)).is_ok());
        let err = finite_slice("seed", &[0.0, f64::NAN]).unwrap_err();
        assert!(err.message().starts_with("seed[1]"));
        let m = pb::Matrix {
            rows: 2,
            cols: 2,
            data: vec![1.0; 3],
        };
        assert!(
            matrix_in("a", Some(&m), 100)
                .unwrap_err()
                .message()
                .starts_with("a.data")
        );
        let row_major = pb::Matrix {
            rows: 1,
            cols: 2,
            data: vec![1.0, 2.0],
        };
        let dm = matrix_in("a", Some(&row_major), 100).unwrap();
        assert_eq!((dm[(0, 0)], dm[(0, 1)]), (1.0, 2.0));
        assert_eq!(matrix_out(&dm).data, vec![1.0, 2.0]);
    }
}
