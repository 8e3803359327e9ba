//! Entry points for coverage-guided fuzzers (`fuzz/`, cargo-fuzz): request
//! messages (decoded from arbitrary bytes by the fuzz target) run through the
//! service's own conversions to domain values, exactly as a call would be,
//! minus the transport. Every outcome but a panic, a hang or unbounded memory is
//! fine: bad input must come back as a `Status`.

use crate::api::scene::scene_in;
use crate::pb;
use kinplan_core::collision::SceneLimits;

/// A `PlanRequest` through the planning and scene conversions.
pub fn convert_plan(r: &pb::PlanRequest) {
    let _ = crate::api::planning::convert::plan_input(r);
    let _ = scene_in("scene", r.scene.as_ref(), &SceneLimits::default());
}

/// An `ExploreRequest` through the exploration loop's conversion (for a UR5).
pub fn convert_explore(r: &pb::ExploreRequest) {
    if let Ok(chain) = kinplan_core::robot::builtin_chain("ur5") {
        let _ = crate::api::exploration::explore_loop::convert::explore_params_in(r, &chain);
    }
}

/// A `NextBestViewRequest` through the next-best-view and camera conversions.
pub fn convert_nbv(r: &pb::NextBestViewRequest) {
    let _ = crate::api::exploration::convert::nbv_params_in(r);
    let _ = crate::api::exploration::convert::camera_in(r.camera.as_ref());
}

#[cfg(test)]
mod tests {
    use super::*;
    use prost::Message;

    /// Decodes `data` as each request with a pure conversion and converts
    /// it, as the `requests` fuzz target does.
    fn convert_requests(data: &[u8]) {
        if let Ok(r) = pb::PlanRequest::decode(data) {
            convert_plan(&r);
        }
        if let Ok(r) = pb::ExploreRequest::decode(data) {
            convert_explore(&r);
        }
        if let Ok(r) = pb::NextBestViewRequest::decode(data) {
            convert_nbv(&r);
        }
    }

    #[test]
    fn hostile_bytes_and_real_requests_convert_without_panicking() {
        convert_requests(&[]);
        convert_requests(&[0xff; 64]);
        let plan = pb::PlanRequest {
            start: vec![f64::NAN; 3],
            scene: Some(pb::Scene {
                objects: vec![pb::CollisionObject {
                    shape: Some(pb::collision_object::Shape::Octree(pb::Octree {
                        id: "OcTree".into(),
                        resolution: 0.1,
                        binary: true,
                        data: vec![0xff; 33],
                    })),
                    ..Default::default()
                }],
            }),
            ..Default::default()
        };
        convert_requests(&plan.encode_to_vec());
        let explore = pb::ExploreRequest {
            resolution: Some(-1.0),
            ..Default::default()
        };
        convert_requests(&explore.encode_to_vec());
    }
}
