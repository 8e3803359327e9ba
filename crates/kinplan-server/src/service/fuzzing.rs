//! Entry points for coverage-guided fuzzers (`fuzz/`, cargo-fuzz): arbitrary
//! bytes decoded as request messages and run through the service's own
//! conversions to domain values, exactly as a call would be, minus the
//! transport. Every outcome but a panic, a hang or unbounded memory is
//! fine: bad input must come back as a `Status`.

use prost::Message;

use super::pb;
use super::scene::scene_in;
use kinplan_core::collision::SceneLimits;

/// Decodes `data` as each request with a pure conversion and converts it.
pub fn convert_requests(data: &[u8]) {
    if let Ok(r) = pb::PlanRequest::decode(data) {
        let _ = super::planning_convert::plan_input(&r);
        let _ = scene_in("scene", r.scene.as_ref(), &SceneLimits::default());
    }
    if let Ok(r) = pb::ExploreRequest::decode(data)
        && let Ok(chain) = kinplan_core::robot::builtin_chain("ur5")
    {
        let _ = super::explore_convert::explore_params_in(&r, &chain);
    }
    if let Ok(r) = pb::NextBestViewRequest::decode(data) {
        let _ = super::exploration_convert::nbv_params_in(&r);
        let _ = super::exploration_convert::camera_in(r.camera.as_ref());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
