//! `Retime`: a client's own joint path timed by the plan room's
//! [`retime`], with the S0 criteria of the result.

use std::time::Instant;

use nalgebra::Isometry3;
use tonic::Status;

use super::convert::{criteria_out, timed_out, timing_in};
use crate::pb;
use crate::status::invalid;
use crate::status::plan::retime_error;
use kinplan_core::Deadline;
use kinplan_core::plan::{TimingParams, retime};
use kinplan_core::robot::Chain;
use kinplan_core::score::{Rows, ScoreInput, ScoreParams, TrajectoryData, score};

/// Most waypoints of one Retime request.
pub const MAX_RETIME_WAYPOINTS: usize = 100_000;

/// A checked Retime request in domain terms.
pub struct RetimeInput {
    /// `n × dof` row-major.
    pub waypoints: Vec<f64>,
    pub params: TimingParams,
}

/// Checks the waypoints (count, one value per joint, finite) and the timing
/// options (the domain's `validate`, fields named under `timing`).
pub fn retime_input(req: &pb::RetimeRequest, dof: usize) -> Result<RetimeInput, Status> {
    let n = req.waypoints.len();
    if n == 0 {
        return Err(invalid("waypoints", "needs at least one waypoint"));
    }
    if n > MAX_RETIME_WAYPOINTS {
        return Err(invalid(
            "waypoints",
            format!("{n} waypoints exceed the limit of {MAX_RETIME_WAYPOINTS}"),
        ));
    }
    let mut waypoints = Vec::with_capacity(n * dof);
    for (i, w) in req.waypoints.iter().enumerate() {
        if w.positions.len() != dof {
            return Err(invalid(
                format!("waypoints[{i}].positions"),
                format!("has {} values, the robot has {dof} joints", w.positions.len()),
            ));
        }
        if let Some(j) = w.positions.iter().position(|v| !v.is_finite()) {
            return Err(invalid(
                format!("waypoints[{i}].positions[{j}]"),
                "must be finite",
            ));
        }
        waypoints.extend_from_slice(&w.positions);
    }
    let params = timing_in("timing", &req.timing.clone().unwrap_or_default())?;
    params.validate(dof).map_err(retime_error)?;
    Ok(RetimeInput { waypoints, params })
}

/// Times the path (polling `deadline`) and scores the result.
pub fn retime_reply(
    chain: &Chain,
    input: &RetimeInput,
    deadline: Deadline<'_>,
) -> Result<pb::RetimeResponse, Status> {
    let dof = chain.dof();
    let v = input.params.velocities(chain);
    let started = Instant::now();
    let tr = retime(&input.waypoints, dof, &v, &input.params, deadline).map_err(retime_error)?;
    let compute_time = started.elapsed().as_secs_f64();
    if deadline.expired() {
        return Err(Status::deadline_exceeded(
            "the deadline passed after timing the path",
        ));
    }
    let poses: Vec<Isometry3<f64>> = tr.q.chunks_exact(dof).map(|q| chain.fk(q)).collect();
    let mut data = TrajectoryData::new(
        Rows::Flat {
            values: &tr.q,
            width: dof,
        },
        &poses,
    );
    data.timestamps = Some(&tr.t);
    let mut scored = ScoreInput::new(data);
    scored.dof = Some(dof);
    let criteria = score(&scored, &ScoreParams::default())
        .map(|r| criteria_out(&r.scores))
        .unwrap_or_default();
    Ok(pb::RetimeResponse {
        trajectory: Some(timed_out(chain, &tr)),
        duration: tr.duration(),
        criteria,
        compute_time,
    })
}
