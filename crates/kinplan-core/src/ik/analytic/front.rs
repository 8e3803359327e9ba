//! The analytic method behind `solve_ik`: every closed-form solution, checked
//! by forward kinematics, ranked by distance to the seed (or configuration
//! first, then distance), as an [`IkResult`].

use super::redundant::ReducedArm;
use super::solve::AnalyticSolution;
use crate::ik::attempt::Clock;
use crate::ik::{IkParams, IkResult, IkSolution, IkStatus, IkTarget, pose_error};
use crate::robot::Chain;

fn solution(
    chain: &Chain,
    arm: &ReducedArm,
    target: &IkTarget,
    s: &AnalyticSolution,
    clock: &Clock<'_>,
) -> IkSolution {
    let joints = arm.expand(&s.joints);
    let e = pose_error(&chain.fk(&joints), target);
    IkSolution {
        joints,
        position_error: e.position,
        orientation_error: e.orientation,
        iterations: 0,
        elapsed_us: clock.elapsed_us(),
        status: IkStatus::Converged,
        attempt: 0,
        history: Vec::new(),
        config: Some(s.config),
        singular: s.singular,
    }
}

/// Solves `target` (a pose) for an analysed arm: every solution inside the
/// limits, each re-checked by forward kinematics against the tolerances of
/// `params`, ranked by Euclidean joint distance to the seed (with
/// `params.analytic.hold_configuration`: the seed's [`ConfigFlags`](super::ConfigFlags)
/// first), at most `params.num_solutions` kept. When none exists, the
/// least-squares branch with the lowest error is the (flagged) best attempt
/// and the stop reason is `MaxIterations`.
pub(crate) fn solve_with(
    chain: &Chain,
    reduced: &ReducedArm,
    target: &IkTarget,
    seed: Option<&[f64]>,
    params: &IkParams,
    clock: &Clock<'_>,
) -> IkResult {
    // validate_request refuses position targets for this method; answer one with
    // nothing rather than panic should a caller skip it
    let nothing = |stop_reason| IkResult {
        solutions: Vec::new(),
        best_attempt: None,
        stop_reason,
        attempts: 0,
        total_iterations: 0,
        elapsed_us: clock.elapsed_us(),
    };
    let IkTarget::Pose(pose) = target else {
        return nothing(IkStatus::MaxIterations);
    };
    // a path of many steps (TrackPath, StreamIk) ends here once the deadline passes
    if let Some(stop) = clock.interrupted() {
        return nothing(stop);
    }
    let arm = &reduced.arm;
    let seed_q: Vec<f64> = seed.map_or_else(|| chain.mid_limits(), <[f64]>::to_vec);
    let seed6 = reduced.reduce(&seed_q);
    let mut raw = Vec::with_capacity(64);
    arm.solve_into(pose, Some(&seed6), &params.analytic, &mut raw);
    let seed_config = arm.config_of(&seed6);
    let dist = |q: &[f64; 6]| q.iter().zip(&seed6).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let hold = params.analytic.hold_configuration;
    raw.sort_by(|a, b| {
        let ka = (hold && a.config != seed_config, dist(&a.joints));
        let kb = (hold && b.config != seed_config, dist(&b.joints));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut solutions = Vec::new();
    let mut interrupted = None;
    for (k, s) in raw.iter().enumerate() {
        if solutions.len() >= params.num_solutions {
            break;
        }
        // whole turns of wide joints can give thousands of candidates
        if k % 256 == 255
            && let Some(stop) = clock.interrupted()
        {
            interrupted = Some(stop);
            break;
        }
        let sol = solution(chain, reduced, target, s, clock);
        if sol.position_error <= params.position_tolerance
            && sol.orientation_error <= params.orientation_tolerance
        {
            solutions.push(sol);
        }
    }
    if solutions.is_empty()
        && let Some(stop) = interrupted
    {
        return nothing(stop);
    }
    let best_attempt = if solutions.is_empty() {
        arm.nearest(pose, Some(&seed6), &params.analytic, &mut raw);
        raw.iter()
            .map(|s| {
                let mut b = solution(chain, reduced, target, s, clock);
                b.status = IkStatus::MaxIterations;
                b
            })
            .min_by(|a, b| {
                (a.position_error + a.orientation_error).total_cmp(&(b.position_error + b.orientation_error))
            })
    } else {
        None
    };
    IkResult {
        stop_reason: if solutions.is_empty() {
            IkStatus::MaxIterations
        } else {
            IkStatus::Converged
        },
        solutions,
        best_attempt,
        attempts: 1,
        total_iterations: 0,
        elapsed_us: clock.elapsed_us(),
    }
}

/// Every closed-form solution of `target` for `chain` as an [`IkResult`]
/// (see [`solve_ik`](crate::ik::solve_ik) with [`IkMethod::Analytic`](crate::ik::IkMethod::Analytic),
/// which this is the same as).
///
/// ```
/// use kinplan_core::ik::{IkParams, IkMethod, IkTarget, analytic::solve_analytic};
/// let chain = kinplan_core::robot::builtin_chain("abb_irb4600_60_205").unwrap();
/// let q = [0.2, 0.3, -0.4, 0.5, 0.6, -0.7];
/// let params = IkParams { method: IkMethod::Analytic, num_solutions: 1000, ..IkParams::default() };
/// let r = solve_analytic(&chain, &IkTarget::Pose(chain.fk(&q)), Some(&q), &params).unwrap();
/// // the seed's own configuration comes first, at distance zero
/// assert!(r.solutions[0].joints.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9));
/// assert!(r.solutions.iter().all(|s| s.position_error < 1e-9));
/// ```
pub fn solve_analytic(
    chain: &Chain,
    target: &IkTarget,
    seed: Option<&[f64]>,
    params: &IkParams,
) -> Result<IkResult, crate::ik::IkError> {
    let p = IkParams {
        method: crate::ik::IkMethod::Analytic,
        ..*params
    };
    crate::ik::solve_ik(chain, target, seed, &p, 0, crate::Deadline::none())
}
