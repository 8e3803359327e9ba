//! The STOMP iteration (docs/planning.md#stomp), with joint-space noise (STOMP) or
//! the Cartesian noise generator and cost (CCSTOMP).

use nalgebra::DVector;
use rayon::prelude::*;

use super::cartesian::{CartesianLine, Deviation, cartesian_noise, noise_ik_params};
use super::clock::{Clock, Interrupt};
use super::costs::{CostModel, Evaluation, resolution_of};
use super::noise::{standard_normal, stream};
use super::stomp_matrices::{MatricesError, StompMatrices};
use super::{CartesianParams, StompParams};
use crate::collision::StateChecker;
use crate::ik::IkSolver;
use crate::robot::Chain;

/// How STOMP's loop ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StompStop {
    /// `iterations_after_valid` iterations after the first valid trajectory.
    Converged,
    /// The iteration cap.
    MaxIterations,
    /// The deadline passed.
    Deadline,
    /// The caller's cancellation was raised.
    Cancelled,
}

/// One iteration as a progress callback sees it.
#[derive(Debug, Clone, Copy)]
pub struct IterationReport<'a> {
    /// 0-based iteration.
    pub iteration: usize,
    /// Total cost of the current trajectory after the iteration.
    pub cost: f64,
    /// Whether the iteration's update was kept (false: reverted).
    pub accepted: bool,
    /// Whether the current trajectory is valid.
    pub valid: bool,
    /// The current trajectory, `timesteps × dof`, row-major.
    pub trajectory: &'a [f64],
}

/// What `stomp_optimize` returns.
#[derive(Debug, Clone)]
pub struct StompOutcome {
    /// The best trajectory found, `timesteps × dof`, row-major.
    pub trajectory: Vec<f64>,
    /// Collision-free and within the Cartesian tolerances (STOMP's own check).
    pub valid: bool,
    /// Total cost before the first iteration and after each one.
    pub cost_history: Vec<f64>,
    /// Iterations run.
    pub iterations: usize,
    /// First iteration whose trajectory was valid (0 = the initial one).
    pub first_valid: Option<usize>,
    /// Why the loop ended.
    pub stop: StompStop,
    /// Per-waypoint Cartesian deviation of the result (CCSTOMP only).
    pub deviation: Vec<Deviation>,
    /// Warm-started IK solves of the noise generator, and how many converged.
    pub noise_ik: (usize, usize),
}

struct Rollout<'c> {
    q: Vec<f64>,
    eps: Vec<f64>,
    z: DVector<f64>,
    x: DVector<f64>,
    eval: Evaluation,
    ik: Option<IkSolver<'c>>,
    ik_stats: (usize, usize),
    done: bool,
}

/// Runs STOMP from `initial` (`timesteps × dof`, row-major; its first and
/// last rows are the fixed start and goal).
///
/// Per iteration (docs/planning.md#stomp): K rollouts `θ + ε_k` — joint noise
/// `ε_d = σ_d L z` with `L Lᵀ = R⁻¹/max R⁻¹`, or with `cartesian` the noise of
/// S0 §3.1 per waypoint — plus up to `max_rollouts − K` best earlier rollouts
/// (their noise taken as `θ_k − θ`) and the noiseless current one; costs
/// `S_k(t)` per timestep; `P_k(t) = e^{−h(S_k(t) − min S(t))/(max S(t) − min S(t))}`
/// normalised over k (uniform when all are equal); `δθ(t) = Σ_k P_k(t) ε_k(t)`;
/// `θ' = θ + M δθ` per joint, clamped into the joint limits; `θ'` replaces `θ`
/// unless its total cost is higher or `θ` is valid and `θ'` is not. Rollouts are drawn and evaluated on the
/// rayon pool; rollout k of iteration i draws from its own stream
/// (seed, i, k), so a seed fixes the result.
///
/// Stops `iterations_after_valid` iterations after the first valid
/// trajectory, at `max_iterations`, or when `clock` is interrupted (checked
/// before every rollout and between phases). Parameters must be validated.
#[allow(clippy::too_many_arguments)]
pub(crate) fn stomp_optimize<C: StateChecker + ?Sized>(
    chain: &Chain,
    checker: &C,
    params: &StompParams,
    cartesian: Option<&CartesianParams>,
    initial: &[f64],
    seed: u64,
    clock: &Clock<'_>,
    progress: &mut dyn FnMut(&IterationReport<'_>),
) -> StompOutcome {
    let dof = chain.dof();
    let n = params.timesteps;
    let free = n - 2;
    let mats = match StompMatrices::new(free, clock.deadline) {
        Ok(m) => m,
        Err(MatricesError::Stopped | MatricesError::Empty) => {
            // Validated parameters have free ≥ 1: only an interruption lands here.
            return StompOutcome {
                trajectory: initial.to_vec(),
                valid: false,
                cost_history: Vec::new(),
                iterations: 0,
                first_valid: None,
                stop: interrupt_stop(clock.interrupted().unwrap_or(Interrupt::Deadline)),
                deviation: Vec::new(),
                noise_ik: (0, 0),
            };
        }
    };
    let model = CostModel {
        chain,
        checker,
        params,
        limits: chain.limits().collect(),
        resolution: resolution_of(checker),
        cartesian: cartesian.map(|c| {
            let line = CartesianLine::between(chain, &initial[..dof], &initial[(n - 1) * dof..]);
            (c, line)
        }),
        n,
        dof,
    };
    let ik_params = cartesian.map(noise_ik_params);
    let keep = params.max_rollouts - params.rollouts;
    let mut slots: Vec<Rollout<'_>> = (0..params.max_rollouts)
        .map(|_| Rollout {
            q: initial.to_vec(),
            eps: vec![0.0; n * dof],
            z: DVector::zeros(free),
            x: DVector::zeros(free),
            eval: Evaluation::new(n, dof),
            ik: cartesian.map(|_| IkSolver::new(chain)),
            ik_stats: (0, 0),
            done: false,
        })
        .collect();
    let mut theta = initial.to_vec();
    let mut cur = Evaluation::new(n, dof);
    let evaluated = model.evaluate(&theta, &mut cur, clock);
    let mut cand_q = theta.clone();
    let mut cand = Evaluation::new(n, dof);
    let mut cost_history = vec![cur.total];
    let mut first_valid = (evaluated && cur.valid()).then_some(0);
    let mut reused = 0usize;
    let mut stop = StompStop::MaxIterations;
    let mut iterations = 0;
    let mut weights = vec![0.0; params.max_rollouts + 1];
    let mut delta = vec![DVector::<f64>::zeros(free); dof];
    let mut update = DVector::<f64>::zeros(free);

    if !evaluated {
        stop = interrupt_stop(clock.interrupted().unwrap_or(Interrupt::Deadline));
    }
    for iter in 0..params.max_iterations {
        if !evaluated {
            break;
        }
        if let Some(fv) = first_valid
            && iter >= fv + params.iterations_after_valid
        {
            stop = StompStop::Converged;
            break;
        }
        if let Some(i) = clock.interrupted() {
            stop = interrupt_stop(i);
            break;
        }
        // Reused rollouts sit in 0..reused; fresh ones follow.
        let active = reused + params.rollouts;
        let theta_ref = &theta;
        slots[..active].par_iter_mut().enumerate().for_each(|(k, slot)| {
            slot.done = false;
            if clock.interrupted().is_some() {
                return;
            }
            if k >= reused {
                let mut rng = stream(seed, iter as u64, (k - reused) as u64);
                slot.eps.iter_mut().for_each(|e| *e = 0.0);
                match (&mut slot.ik, cartesian, &ik_params) {
                    (Some(solver), Some(cp), Some(ikp)) => {
                        for t in 1..n - 1 {
                            let range = t * dof..(t + 1) * dof;
                            let ok = cartesian_noise(
                                solver,
                                &theta_ref[range.clone()],
                                cp,
                                ikp,
                                &mut rng,
                                clock.deadline,
                                &mut slot.eps[range],
                            );
                            slot.ik_stats.0 += 1;
                            slot.ik_stats.1 += ok as usize;
                        }
                    }
                    _ => {
                        for d in 0..dof {
                            for v in slot.z.iter_mut() {
                                *v = standard_normal(&mut rng);
                            }
                            mats.sample_noise(params.stddev(d), &slot.z, &mut slot.x);
                            for t in 0..free {
                                slot.eps[(t + 1) * dof + d] = slot.x[t];
                            }
                        }
                    }
                }
                for ((q, th), e) in slot.q.iter_mut().zip(theta_ref).zip(&slot.eps) {
                    *q = th + e;
                }
                if !model.evaluate(&slot.q, &mut slot.eval, clock) {
                    return;
                }
            } else {
                for ((e, q), th) in slot.eps.iter_mut().zip(&slot.q).zip(theta_ref) {
                    *e = q - th;
                }
            }
            slot.done = true;
        });
        if let Some(i) = clock.interrupted() {
            stop = interrupt_stop(i);
            break;
        }
        // Probabilities per timestep over the rollouts and the current θ.
        delta.iter_mut().for_each(|v| v.fill(0.0));
        for t in 1..n - 1 {
            let (mut lo, mut hi) = (cur.at(t), cur.at(t));
            for s in &slots[..active] {
                lo = lo.min(s.eval.at(t));
                hi = hi.max(s.eval.at(t));
            }
            let span = hi - lo;
            let mut sum = 0.0;
            for (k, s) in slots[..active].iter().enumerate() {
                let x = if span > 0.0 {
                    (s.eval.at(t) - lo) / span
                } else {
                    0.0
                };
                weights[k] = (-params.cost_sensitivity * x).exp();
                sum += weights[k];
            }
            let x = if span > 0.0 { (cur.at(t) - lo) / span } else { 0.0 };
            sum += (-params.cost_sensitivity * x).exp(); // ε = 0: adds nothing to δθ
            for (k, s) in slots[..active].iter().enumerate() {
                let p = weights[k] / sum;
                for (d, dv) in delta.iter_mut().enumerate() {
                    dv[t - 1] += p * s.eps[t * dof + d];
                }
            }
        }
        // θ' = θ + M δθ, clamped into the limits.
        cand_q.copy_from_slice(&theta);
        for (d, dv) in delta.iter().enumerate() {
            mats.project(dv, &mut update);
            let (lo, hi) = model.limits[d];
            for t in 0..free {
                let v = &mut cand_q[(t + 1) * dof + d];
                *v = (*v + update[t]).clamp(lo, hi);
            }
        }
        if !model.evaluate(&cand_q, &mut cand, clock) {
            stop = interrupt_stop(clock.interrupted().unwrap_or(Interrupt::Deadline));
            break;
        }
        // Revert on a cost rise, and never trade a valid trajectory for an
        // invalid one (a lower distance cost can outweigh a small collision
        // penalty).
        let accepted = cand.total <= cur.total && (cand.valid() || !cur.valid());
        if accepted {
            std::mem::swap(&mut theta, &mut cand_q);
            std::mem::swap(&mut cur, &mut cand);
        }
        iterations = iter + 1;
        cost_history.push(cur.total);
        if first_valid.is_none() && cur.valid() {
            first_valid = Some(iterations);
        }
        progress(&IterationReport {
            iteration: iter,
            cost: cur.total,
            accepted,
            valid: cur.valid(),
            trajectory: &theta,
        });
        // Keep the best `keep` rollouts at the front for the next iteration.
        slots[..active].sort_by(|a, b| a.eval.total.total_cmp(&b.eval.total));
        reused = keep.min(active);
    }
    if stop == StompStop::MaxIterations
        && let Some(fv) = first_valid
        && iterations >= fv + params.iterations_after_valid
    {
        stop = StompStop::Converged;
    }
    let noise_ik = slots
        .iter()
        .fold((0, 0), |a, s| (a.0 + s.ik_stats.0, a.1 + s.ik_stats.1));
    StompOutcome {
        valid: evaluated && cur.valid(),
        deviation: cur.deviation.clone(),
        trajectory: theta,
        cost_history,
        iterations,
        first_valid,
        stop,
        noise_ik,
    }
}

fn interrupt_stop(i: Interrupt) -> StompStop {
    match i {
        Interrupt::Deadline => StompStop::Deadline,
        Interrupt::Cancelled => StompStop::Cancelled,
    }
}

/// `n` waypoints evenly spaced on the straight joint-space line `a → b`,
/// row-major.
pub(crate) fn straight_line(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(n * a.len());
    for t in 0..n {
        let s = t as f64 / (n - 1) as f64;
        out.extend(a.iter().zip(b).map(|(x, y)| x + s * (y - x)));
    }
    // exact ends
    let dof = a.len();
    out[..dof].copy_from_slice(a);
    out[(n - 1) * dof..].copy_from_slice(b);
    out
}
