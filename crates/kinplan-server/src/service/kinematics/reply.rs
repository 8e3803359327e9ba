//! Domain answers and errors into replies and statuses naming the request field.

use super::*;

pub(super) fn micros(d: Duration) -> u64 {
    d.as_micros().min(u64::MAX as u128) as u64
}

pub(super) fn status_out(s: IkStatus) -> i32 {
    (match s {
        IkStatus::Converged => pb::IkStatus::Converged,
        IkStatus::MaxIterations => pb::IkStatus::MaxIterations,
        IkStatus::Stalled => pb::IkStatus::Stalled,
        IkStatus::TimeBudget => pb::IkStatus::TimeBudget,
        IkStatus::Cancelled => pb::IkStatus::Cancelled,
    }) as i32
}

pub(super) fn solution_out(s: IkSolution) -> pb::IkSolution {
    pb::IkSolution {
        joints: s.joints,
        position_error: s.position_error,
        orientation_error: s.orientation_error,
        iterations: s.iterations as u32,
        elapsed_us: s.elapsed_us,
        status: status_out(s.status),
        attempt: s.attempt as u32,
        position_error_history: s.history.iter().map(|h| h.0).collect(),
        orientation_error_history: s.history.iter().map(|h| h.1).collect(),
    }
}

pub(super) fn result_out(r: IkResult) -> pb::SolveIkResponse {
    pb::SolveIkResponse {
        success: r.success(),
        status: status_out(r.stop_reason),
        attempts: r.attempts as u32,
        total_iterations: r.total_iterations as u64,
        elapsed_us: r.elapsed_us,
        solutions: r.solutions.into_iter().map(solution_out).collect(),
        best_attempt: r.best_attempt.map(solution_out),
        model_id: Vec::new(),
    }
}

pub(super) fn track_out(
    r: TrackResult,
    poses: &[Isometry3<f64>],
    model_id: Vec<u8>,
) -> pb::TrackPathResponse {
    pb::TrackPathResponse {
        steps: r
            .steps
            .into_iter()
            .zip(poses)
            .map(|(s, pose)| pb::TrackStep {
                target: Some(pose_out(pose)),
                joints: s.joints,
                position_error: s.position_error,
                orientation_error: s.orientation_error,
                iterations: s.iterations as u32,
                elapsed_us: s.elapsed_us,
                status: status_out(s.status),
                max_joint_step: s.max_joint_step,
            })
            .collect(),
        all_converged: r.all_converged,
        max_joint_step: r.max_joint_step,
        elapsed_us: r.elapsed_us,
        status: status_out(r.stop_reason),
        model_id,
    }
}

pub(super) fn linear_out(s: LinearSolution, elapsed: Duration) -> pb::SolveLinearSystemResponse {
    pb::SolveLinearSystemResponse {
        x: s.x.iter().copied().collect(),
        residual_norm: s.residual_norm,
        iterations: s.iterations as u32,
        status: (match s.status {
            SolveStatus::Converged => pb::LinearSolveStatus::Converged,
            SolveStatus::IterationCap => pb::LinearSolveStatus::IterationCap,
        }) as i32,
        residual_history: s.history,
        elapsed_us: micros(elapsed),
    }
}
