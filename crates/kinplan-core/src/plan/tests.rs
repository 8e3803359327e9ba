//! Planner tests on closed-form toy worlds, each result re-checked by an
//! independent fine-resolution check.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use super::toy::{JointBoxes, PlanarWorld, fine_valid};
use super::*;
use crate::Deadline;
use crate::collision::StateChecker;
use crate::robot::{Chain, builtin_chain};

fn planar3() -> std::sync::Arc<Chain> {
    builtin_chain("planar_3").unwrap()
}

fn blocked_request(algorithm: Algorithm) -> PlanRequest {
    PlanRequest {
        start: vec![-1.3, 0.0, 0.0],
        goal: Goal::Joints(vec![1.3, 0.0, 0.0]),
        algorithm,
        seed: 7,
        ..Default::default()
    }
}

fn assert_ends(r: &PlanResult, start: &[f64], goal: &[f64]) {
    let d = r.dof;
    assert_eq!(&r.q[..d], start, "start not kept exactly");
    assert_eq!(&r.q[r.q.len() - d..], goal, "goal not kept exactly");
}

#[test]
fn the_toy_world_blocks_the_straight_line() {
    let w = PlanarWorld::planar3_blocked();
    assert!(w.is_valid(&[-1.3, 0.0, 0.0]) && w.is_valid(&[1.3, 0.0, 0.0]));
    assert!(!w.motion_valid(&[-1.3, 0.0, 0.0], &[1.3, 0.0, 0.0]));
}

#[test]
fn stomp_from_the_straight_line_goes_around_the_circle() {
    // A small circle the straight arm's tip sweeps through: STOMP alone
    // (MoveIt's h = 0.5, no RRT-Connect start) must bend the arm around it.
    let chain = planar3();
    let mut w = PlanarWorld::planar3_blocked();
    w.circles = vec![(0.9, 0.0, 0.06)];
    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.initial = InitialTrajectory::StraightLine;
    req.stomp.timesteps = 20;
    req.stomp.max_iterations = 200;
    req.stomp.noise_stddev = vec![1.0];
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded, "history {:?}", r.cost_history);
    assert_eq!(r.q.len(), 20 * 3);
    assert!(
        fine_valid(&w.shrunk(0.02), &r.q, 3, 0.001),
        "independent check found a collision"
    );
    assert_ends(&r, &[-1.3, 0.0, 0.0], &[1.3, 0.0, 0.0]);
    // the cost never rises (reverted updates keep the old θ)
    assert!(r.cost_history.windows(2).all(|c| c[1] <= c[0]));
    assert!(r.cost_history[0] > *r.cost_history.last().unwrap());
}

#[test]
fn stomp_and_rrt_connect_succeed_from_a_blocked_line_and_recheck_clean() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    for alg in [Algorithm::Stomp, Algorithm::RrtConnect] {
        let r = plan(&chain, &w, &blocked_request(alg), PlanControl::default()).unwrap();
        assert_eq!(r.status, PlanStatus::Succeeded, "{alg:?}");
        assert!(r.valid);
        assert!(
            fine_valid(&w.shrunk(0.02), &r.q, 3, 0.001),
            "{alg:?}: independent check found a collision"
        );
        assert_ends(&r, &[-1.3, 0.0, 0.0], &[1.3, 0.0, 0.0]);
        assert!(r.criteria.is_some_and(|c| c.jd > 0.0));
    }
}

#[test]
fn rrt_connect_threads_a_narrow_joint_space_passage() {
    // A wall at 0.4 < q0 < 0.6 with one 0.1-wide hole at 0.5 < q1 < 0.6.
    let wall = |lo1: f64, hi1: f64| (vec![0.4, lo1, -10.0], vec![0.6, hi1, 10.0]);
    let w = JointBoxes {
        dof: 3,
        limit: std::f64::consts::PI,
        boxes: vec![wall(-10.0, 0.5), wall(0.6, 10.0)],
    };
    let chain = planar3();
    let req = PlanRequest {
        start: vec![0.0, -1.0, 0.0],
        goal: Goal::Joints(vec![1.0, 1.0, 0.3]),
        algorithm: Algorithm::RrtConnect,
        seed: 3,
        ..Default::default()
    };
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded);
    assert!(fine_valid(&w.shrunk(0.01), &r.q, 3, 0.001));
    assert_ends(&r, &[0.0, -1.0, 0.0], &[1.0, 1.0, 0.3]);
}

#[test]
fn a_blend_cutting_into_the_wall_makes_the_time_optimal_plan_invalid() {
    // the narrow passage above: with corners rounded by up to 0.5 rad the
    // timed trajectory enters the wall (checked here state by state at
    // 0.001 rad), and the plan must not call it valid
    let wall = |lo1: f64, hi1: f64| (vec![0.4, lo1, -10.0], vec![0.6, hi1, 10.0]);
    let w = JointBoxes {
        dof: 3,
        limit: std::f64::consts::PI,
        boxes: vec![wall(-10.0, 0.5), wall(0.6, 10.0)],
    };
    let chain = planar3();
    let mut req = PlanRequest {
        start: vec![0.0, -1.0, 0.0],
        goal: Goal::Joints(vec![1.0, 1.0, 0.3]),
        algorithm: Algorithm::RrtConnect,
        seed: 1,
        ..Default::default()
    };
    req.timing.method = TimingMethod::TimeOptimal;
    req.timing.acceleration_limits = Some(vec![2.0; 3]);
    req.timing.path_tolerance = 1e-3;
    // the tight blends stay as clear of the wall as the polyline (which may
    // graze it between the states checked at 0.02 rad)
    let tight = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert!(fine_valid(&w.shrunk(0.01), &tight.trajectory.q, 3, 0.001));
    req.timing.path_tolerance = 0.5;
    let loose = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(loose.q, tight.q, "the same planned waypoints");
    assert!(
        !fine_valid(&w, &loose.trajectory.q, 3, 0.001),
        "the loose blends should cut into the wall"
    );
    assert!(!loose.valid && loose.status == PlanStatus::NoValidTrajectory);
}

#[test]
fn the_same_seed_gives_the_same_trajectory_on_any_pool() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    for alg in [Algorithm::Stomp, Algorithm::RrtConnect] {
        let req = blocked_request(alg);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| plan(&chain, &w, &req, PlanControl::default()).unwrap())
        };
        let (a, b, c) = (run(1), run(2), run(2));
        assert_eq!(a.q, b.q, "{alg:?}: 1 vs 2 threads");
        assert_eq!(b.q, c.q);
        assert_eq!(a.cost_history, b.cost_history);
        let mut other = req.clone();
        other.seed = 8;
        let d = plan(&chain, &w, &other, PlanControl::default()).unwrap();
        assert_ne!(a.q, d.q, "{alg:?}: another seed, same answer");
    }
}

#[test]
fn a_10_ms_budget_answers_within_about_10_ms() {
    let chain = planar3();
    let mut w = PlanarWorld::planar3_blocked();
    w.spin = 2_000; // ~tens of µs per state check
    for alg in [Algorithm::Stomp, Algorithm::RrtConnect] {
        let mut req = blocked_request(alg);
        req.stomp.initial = InitialTrajectory::StraightLine;
        let t0 = Instant::now();
        // an own pool: rollouts of tests running beside this one on the
        // global pool would otherwise delay ours
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let r = pool.install(|| {
            let ctl = PlanControl {
                deadline: Deadline::at(t0 + Duration::from_millis(10)),
                ..Default::default()
            };
            plan(&chain, &w, &req, ctl).unwrap()
        });
        let took = t0.elapsed();
        // the re-check and timing after the deadline cost a few state checks
        assert!(took < Duration::from_millis(40), "{alg:?} took {took:?}");
        assert!(
            matches!(r.status, PlanStatus::Timeout | PlanStatus::Succeeded),
            "{alg:?}: {:?}",
            r.status
        );
    }
}

/// Regression: STOMP's setup was cubic in the timesteps and could not be
/// interrupted (10,000 timesteps answered long after any deadline and held
/// gigabytes). The banded matrices build in linear memory and poll the clock.
#[test]
fn stomp_with_the_most_timesteps_answers_by_its_deadline() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    for budget_ms in [5, 60] {
        let mut req = blocked_request(Algorithm::Stomp);
        req.stomp.timesteps = 10_000;
        req.stomp.initial = InitialTrajectory::StraightLine;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let t0 = Instant::now();
        let r = pool.install(|| {
            let ctl = PlanControl {
                deadline: Deadline::at(t0 + Duration::from_millis(budget_ms)),
                ..Default::default()
            };
            plan(&chain, &w, &req, ctl).unwrap()
        });
        let took = t0.elapsed();
        // a few milliseconds past the deadline on a quiet machine (timing and
        // scoring the 10,000 waypoints); the margin is for a loaded CI host
        assert!(
            took < Duration::from_millis(budget_ms + 250),
            "{budget_ms} ms budget took {took:?}"
        );
        assert_eq!(r.status, PlanStatus::Timeout, "{budget_ms} ms budget");
    }
}

#[test]
fn cancellation_is_a_status() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    let calls = AtomicUsize::new(0);
    let stop = || calls.fetch_add(1, Ordering::Relaxed) > 3;
    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.initial = InitialTrajectory::StraightLine;
    let ctl = PlanControl {
        deadline: Deadline::none().with_cancel(&stop),
        ..Default::default()
    };
    let r = plan(&chain, &w, &req, ctl).unwrap();
    assert_eq!(r.status, PlanStatus::Cancelled);
    assert_eq!(r.q.len(), 40 * 3, "best so far returned");
}

#[test]
fn invalid_start_and_goal_are_statuses_and_bad_parameters_errors() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    let mut req = blocked_request(Algorithm::Stomp);
    req.start = vec![0.0, 0.0, 0.0]; // straight arm through the circle
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::InvalidStart);
    assert!(r.q.is_empty());
    let mut req = blocked_request(Algorithm::RrtConnect);
    req.goal = Goal::Joints(vec![0.0, 0.0, 0.0]);
    assert_eq!(
        plan(&chain, &w, &req, PlanControl::default()).unwrap().status,
        PlanStatus::InvalidGoal
    );
    // goal outside the limits
    req.goal = Goal::Joints(vec![4.0, 0.0, 0.0]);
    assert_eq!(
        plan(&chain, &w, &req, PlanControl::default()).unwrap().status,
        PlanStatus::InvalidGoal
    );

    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.timesteps = 2;
    let e = plan(&chain, &w, &req, PlanControl::default()).unwrap_err();
    assert!(
        matches!(
            e,
            PlanError::InvalidParam {
                field: PlanField::Timesteps,
                ..
            }
        ),
        "{e}"
    );
    let mut req = blocked_request(Algorithm::Stomp);
    req.start = vec![0.0, f64::NAN, 0.0];
    let e = plan(&chain, &w, &req, PlanControl::default()).unwrap_err();
    assert_eq!(
        e,
        PlanError::NonFinite {
            field: PlanField::Start,
            index: 1
        }
    );
    let mut req = blocked_request(Algorithm::Stomp);
    req.goal = Goal::Joints(vec![0.0]);
    let e = plan(&chain, &w, &req, PlanControl::default()).unwrap_err();
    assert!(matches!(
        e,
        PlanError::WrongLength {
            field: PlanField::GoalJoints,
            ..
        }
    ));
    let mut req = blocked_request(Algorithm::Ccstomp);
    req.cartesian.rotation_tolerance = -1.0;
    let e = plan(&chain, &w, &req, PlanControl::default()).unwrap_err();
    assert!(matches!(
        e,
        PlanError::InvalidParam {
            field: PlanField::RotationTolerance,
            ..
        }
    ));
    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.max_rollouts = 3;
    assert!(plan(&chain, &w, &req, PlanControl::default()).is_err());
}

#[test]
fn progress_sees_every_iteration_with_a_never_rising_cost() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.initial = InitialTrajectory::StraightLine;
    req.stomp.max_iterations = 20;
    req.stomp.iterations_after_valid = 100;
    let mut seen = Vec::new();
    let mut valid = Vec::new();
    let mut cb = |it: &IterationReport<'_>| {
        seen.push((it.iteration, it.cost, it.trajectory.len()));
        valid.push(it.valid);
    };
    let ctl = PlanControl {
        progress: Some(&mut cb),
        ..Default::default()
    };
    let r = plan(&chain, &w, &req, ctl).unwrap();
    assert_eq!(seen.len(), 20);
    assert_eq!(r.iterations, 20);
    assert!(seen.iter().enumerate().all(|(i, s)| s.0 == i && s.2 == 120));
    assert!(seen.windows(2).all(|p| p[1].1 <= p[0].1));
    // once valid, never invalid again
    assert!(valid.windows(2).all(|v| !v[0] || v[1]), "{valid:?}");
}

/// Velocity and acceleration of a timed piecewise-linear path, computed
/// here from the definitions (not with the planner's code).
fn worst_rates(q: &[f64], t: &[f64], dof: usize, v: &[f64], a: &[f64]) -> (f64, f64) {
    let n = t.len();
    let vel = |s: usize, j: usize| (q[(s + 1) * dof + j] - q[s * dof + j]) / (t[s + 1] - t[s]);
    let mut worst_v: f64 = 0.0;
    let mut worst_a: f64 = 0.0;
    for j in 0..dof {
        for s in 0..n - 1 {
            worst_v = worst_v.max(vel(s, j).abs() / v[j]);
        }
        for i in 0..n {
            let vin = if i > 0 { vel(i - 1, j) } else { 0.0 };
            let vout = if i + 1 < n { vel(i, j) } else { 0.0 };
            let span = match i {
                0 => (t[1] - t[0]) / 2.0,
                _ if i + 1 == n => (t[n - 1] - t[n - 2]) / 2.0,
                _ => (t[i + 1] - t[i - 1]) / 2.0,
            };
            worst_a = worst_a.max((vout - vin).abs() / span / a[j]);
        }
    }
    (worst_v, worst_a)
}

#[test]
fn time_parameterisation_never_exceeds_the_limits() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    for case in 0..200 {
        let dof = rng.random_range(1..7);
        let n = rng.random_range(2..30);
        let q: Vec<f64> = (0..n * dof).map(|_| rng.random_range(-2.0..2.0)).collect();
        let v: Vec<f64> = (0..dof).map(|_| rng.random_range(0.2..3.0)).collect();
        let a: Vec<f64> = (0..dof).map(|_| rng.random_range(0.5..10.0)).collect();
        let t = time_parameterize(&q, dof, &v, None);
        assert!(t.windows(2).all(|w| w[1] > w[0]));
        assert!(
            worst_rates(&q, &t, dof, &v, &[f64::INFINITY; 6]).0 <= 1.0 + 1e-9,
            "case {case}"
        );
        // some segment runs a joint at its limit: no slower than needed
        let (wv, _) = worst_rates(&q, &t, dof, &v, &[f64::INFINITY; 6]);
        assert!(wv > 1.0 - 1e-9 || t[n - 1] <= MIN_SEGMENT_TIME * n as f64);
        let t = time_parameterize(&q, dof, &v, Some(&a));
        let (wv, wa) = worst_rates(&q, &t, dof, &v, &a);
        assert!(wv <= 1.0 + 1e-9 && wa <= 1.0 + 1e-9, "case {case}: v {wv} a {wa}");
    }
}

#[test]
fn returned_trajectories_are_timed_within_the_chain_velocity_limits() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    let r = plan(
        &chain,
        &w,
        &blocked_request(Algorithm::Stomp),
        PlanControl::default(),
    )
    .unwrap();
    let v: Vec<f64> = chain.joints().iter().map(|j| j.max_velocity.unwrap()).collect();
    let (wv, _) = worst_rates(&r.q, &r.time_from_start, 3, &v, &[f64::INFINITY; 3]);
    assert!(wv <= 1.0 + 1e-9 && wv > 0.99, "{wv}");
}

#[test]
fn ccstomp_keeps_every_waypoint_within_the_tolerances() {
    // UR5 in free space (limits only), S0's noise and tolerances, tighter t_r.
    let chain = builtin_chain("ur5").unwrap();
    struct Free(Vec<(f64, f64)>);
    impl StateChecker for Free {
        fn dof(&self) -> usize {
            self.0.len()
        }
        fn is_valid(&self, q: &[f64]) -> bool {
            q.iter().zip(&self.0).all(|(v, (lo, hi))| v >= lo && v <= hi)
        }
        fn clearance(&self, _: &[f64], d: f64) -> f64 {
            d
        }
    }
    let w = Free(chain.limits().collect());
    let mut req = PlanRequest {
        start: vec![0.0, -1.2, 1.4, -0.8, 1.1, 0.2],
        goal: Goal::Joints(vec![1.2, -1.0, 1.0, -1.2, 1.3, -0.4]),
        algorithm: Algorithm::Ccstomp,
        seed: 5,
        ..Default::default()
    };
    req.stomp.timesteps = 10;
    req.cartesian.translation_tolerance = 0.08;
    req.cartesian.rotation_tolerance = 0.1;
    // noise scaled to these tighter tolerances (S0's 0.5 m suits t_t = 1 m)
    req.cartesian.translation_stddev = 0.05;
    req.cartesian.rotation_stddev = 0.05;
    req.stomp.max_iterations = 100;
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded, "history {:?}", r.cost_history);
    let line = CartesianLine::between(&chain, &req.start, &[1.2, -1.0, 1.0, -1.2, 1.3, -0.4]);
    for (i, q) in r.q.chunks_exact(6).enumerate() {
        // independent: the reference pose and the deviation by matrices
        let pl = line.pose_at(i as f64 / 9.0).to_homogeneous();
        let pr = chain.fk(q).to_homogeneous();
        let diff = pl.try_inverse().unwrap() * pr;
        let et = diff.fixed_view::<3, 1>(0, 3).norm();
        let tr = diff.fixed_view::<3, 3>(0, 0).trace();
        let er = ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos();
        assert!(et <= 0.08 && er <= 0.1, "waypoint {i}: {et} m, {er} rad");
        assert!(
            (r.deviation[i].translation - et).abs() < 1e-9 && (r.deviation[i].rotation - er).abs() < 1e-6
        );
    }
    // the straight joint line itself leaves the tolerance, so CCSTOMP did work
    let mut straight = req.clone();
    straight.algorithm = Algorithm::RrtConnect;
    let s = plan(&chain, &w, &straight, PlanControl::default()).unwrap();
    assert_eq!(
        s.q.len(),
        12,
        "free space: RRT-Connect returns the straight motion"
    );
    let mut mid = vec![0.0; 6];
    for (j, m) in mid.iter_mut().enumerate() {
        *m = 0.5 * (s.q[j] + s.q[6 + j]);
    }
    let d = deviation(&line.pose_at(0.5), &chain.fk(&mid));
    assert!(d.translation > 0.08 || d.rotation > 0.1, "{d:?}");
}

#[test]
fn a_pose_goal_is_solved_by_ik_and_reached() {
    let chain = builtin_chain("ur5").unwrap();
    let w = JointBoxes {
        dof: 6,
        limit: 2.0 * std::f64::consts::PI,
        boxes: vec![],
    };
    let target = chain.fk(&[0.8, -1.0, 1.2, -1.0, 1.2, 0.1]);
    let req = PlanRequest {
        start: vec![0.0, -1.2, 1.4, -0.8, 1.1, 0.2],
        goal: Goal::Pose(target),
        algorithm: Algorithm::RrtConnect,
        ..Default::default()
    };
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded);
    let end = chain.fk(&r.q[r.q.len() - 6..]);
    let d = deviation(&target, &end);
    assert!(d.translation < 1e-4 && d.rotation < 1e-3);
    assert_eq!(r.goal.as_deref(), Some(&r.q[r.q.len() - 6..]));
    // unreachable pose
    let mut far = req.clone();
    far.goal = Goal::Pose(nalgebra::Isometry3::translation(5.0, 0.0, 0.0));
    far.goal_ik.max_restarts = 3;
    assert_eq!(
        plan(&chain, &w, &far, PlanControl::default()).unwrap().status,
        PlanStatus::GoalUnreachable
    );
}

/// The goal IK runs under the request's deadline: an unreachable pose with
/// restarts enough for seconds is cut at the deadline and reported as a
/// timeout (or a cancellation), not as an unreachable goal.
#[test]
fn the_goal_ik_stops_at_the_deadline_and_says_so() {
    let chain = builtin_chain("ur5").unwrap();
    let w = JointBoxes {
        dof: 6,
        limit: 2.0 * std::f64::consts::PI,
        boxes: vec![],
    };
    let mut req = PlanRequest {
        start: vec![0.0, -1.2, 1.4, -0.8, 1.1, 0.2],
        goal: Goal::Pose(nalgebra::Isometry3::translation(5.0, 0.0, 0.0)),
        algorithm: Algorithm::RrtConnect,
        ..Default::default()
    };
    req.goal_ik.max_restarts = usize::MAX;
    req.goal_ik.time_budget = None;
    let t0 = Instant::now();
    let ctl = PlanControl {
        deadline: Deadline::at(t0 + Duration::from_millis(20)),
        ..Default::default()
    };
    let r = plan(&chain, &w, &req, ctl).unwrap();
    assert_eq!(r.status, PlanStatus::Timeout);
    // generous slack for a loaded 2-core machine
    assert!(t0.elapsed() < Duration::from_millis(500), "{:?}", t0.elapsed());
    let stop = || true;
    let ctl = PlanControl {
        deadline: Deadline::none().with_cancel(&stop),
        ..Default::default()
    };
    assert_eq!(plan(&chain, &w, &req, ctl).unwrap().status, PlanStatus::Cancelled);
}

#[test]
fn resampling_keeps_every_vertex_and_the_count() {
    let path = [0.0, 0.0, 1.0, 0.0, 1.0, 3.0];
    let q = super::rrt_connect::resample(&path, 2, 8);
    assert_eq!(q.len(), 16);
    let rows: Vec<&[f64]> = q.chunks_exact(2).collect();
    assert_eq!(rows[0], &[0.0, 0.0]);
    assert!(rows.contains(&&[1.0, 0.0][..]), "corner kept");
    assert_eq!(rows[7], &[1.0, 3.0]);
    // the 3 m segment gets three times the points of the 1 m one
    let on_first = rows
        .iter()
        .filter(|r| r[1] == 0.0 && r[0] > 0.0 && r[0] < 1.0)
        .count();
    let on_second = rows
        .iter()
        .filter(|r| r[0] == 1.0 && r[1] > 0.0 && r[1] < 3.0)
        .count();
    assert_eq!((on_first, on_second), (1, 4));
}

/// A UR5 in free space, CCSTOMP between two states with 2 cm / 0.02 rad
/// tolerances: chain, world, request, goal.
fn ur5_ccstomp_request() -> (std::sync::Arc<Chain>, JointBoxes, PlanRequest, Vec<f64>) {
    let chain = builtin_chain("ur5").unwrap();
    let w = JointBoxes {
        dof: 6,
        limit: 2.0 * std::f64::consts::PI,
        boxes: vec![],
    };
    let goal = vec![0.6, -1.0, 1.2, -1.0, 1.3, 0.0];
    let mut req = PlanRequest {
        start: vec![0.0, -1.2, 1.4, -0.8, 1.1, 0.2],
        goal: Goal::Joints(goal.clone()),
        algorithm: Algorithm::Ccstomp,
        seed: 2,
        ..Default::default()
    };
    req.stomp.timesteps = 12;
    req.cartesian.translation_tolerance = 0.02;
    req.cartesian.rotation_tolerance = 0.02;
    (chain, w, req, goal)
}

#[test]
fn ccstomp_from_the_cartesian_line_stays_on_it() {
    let (chain, w, mut req, goal) = ur5_ccstomp_request();
    req.stomp.initial = InitialTrajectory::CartesianLine;
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded);
    assert_ends(&r, &req.start, &goal);
    assert!(
        r.deviation
            .iter()
            .all(|d| d.translation <= 0.02 && d.rotation <= 0.02)
    );
}

#[test]
fn a_shortcut_resolution_outside_zero_to_one_is_an_error_naming_it() {
    let chain = planar3();
    let w = PlanarWorld::planar3_blocked();
    for bad in [0.0, -0.01, 1.5, f64::NAN, f64::INFINITY] {
        let mut req = blocked_request(Algorithm::RrtConnect);
        req.rrt.shortcut_resolution = Some(bad);
        let e = plan(&chain, &w, &req, PlanControl::default()).unwrap_err();
        assert!(
            matches!(
                e,
                PlanError::InvalidParam {
                    field: PlanField::ShortcutResolution,
                    ..
                }
            ),
            "{bad}: {e}"
        );
        assert!(e.to_string().contains("rrt.shortcut_resolution"), "{e}");
    }
    // A finer shortcut check still returns a valid path with the same ends.
    let mut req = blocked_request(Algorithm::RrtConnect);
    req.rrt.shortcut_resolution = Some(0.01);
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded);
    assert!(r.valid);
    assert_eq!(&r.q[..3], &req.start[..]);
}

#[test]
fn ccstomp_starts_on_the_cartesian_line_unless_told_otherwise() {
    // The request of the test above without a chosen start: CCSTOMP takes the
    // Cartesian line and keeps 2 cm / 0.02 rad; from the joint line (free
    // here, so RRT_CONNECT_IF_BLOCKED keeps it) it does not get there.
    let (chain, w, mut req, goal) = ur5_ccstomp_request();
    assert_eq!(req.stomp.initial, InitialTrajectory::ForAlgorithm);
    let within = |r: &crate::plan::PlanResult| {
        // deviations recomputed from FK of the returned joints
        let line = crate::plan::CartesianLine::between(&chain, &req.start, &goal);
        let n = r.q.len() / 6;
        r.q.chunks_exact(6).enumerate().all(|(t, q)| {
            let d = crate::plan::deviation(&line.pose_at_waypoint(t, n), &chain.fk(q));
            d.translation <= 0.02 + 1e-9 && d.rotation <= 0.02 + 1e-9
        })
    };
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::Succeeded);
    assert!(within(&r));
    req.stomp.initial = InitialTrajectory::RrtConnectIfBlocked;
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert!(!within(&r), "from the joint line the tolerances are not kept");
    // STOMP's own start stays the joint line (or RRT-Connect when blocked)
    assert_eq!(
        InitialTrajectory::ForAlgorithm.for_algorithm(Algorithm::Stomp),
        InitialTrajectory::RrtConnectIfBlocked
    );
}

/// A padded-motion checker for a 2 cm sphere on an x–y slide (±0.5 m)
/// among `obstacle`.
fn slide_checker(obstacle: crate::collision::Obstacle) -> crate::collision::SceneChecker {
    use crate::collision::{
        AllowedCollisions, CheckerParams, RobotModel, Scene, SceneChecker, SceneGeometry, SceneLimits,
    };
    use crate::robot::{ChainSpec, UrdfLimits, parse_chain};
    let urdf = r#"<robot name="slide"><link name="base"/><link name="px"/>
      <link name="probe"><collision><geometry><sphere radius="0.02"/></geometry></collision></link>
      <joint name="jx" type="prismatic"><parent link="base"/><child link="px"/><axis xyz="1 0 0"/>
        <limit lower="-0.5" upper="0.5" effort="0" velocity="1"/></joint>
      <joint name="jy" type="prismatic"><parent link="px"/><child link="probe"/><axis xyz="0 1 0"/>
        <limit lower="-0.5" upper="0.5" effort="0" velocity="1"/></joint></robot>"#;
    let chain = std::sync::Arc::new(parse_chain(urdf, &ChainSpec::default(), UrdfLimits::default()).unwrap());
    let model = std::sync::Arc::new(RobotModel::new(chain).unwrap());
    let acm = AllowedCollisions::adjacent(&model);
    let scene = Scene::new(vec![obstacle], &SceneLimits::default()).unwrap();
    let world = std::sync::Arc::new(SceneGeometry::build(&scene).unwrap());
    let params = CheckerParams {
        padded_motion: true,
        ..CheckerParams::default()
    };
    SceneChecker::new(model, &acm, world, params).unwrap()
}

/// Every state of the straight slide motion `a → b`, 2,000 steps, valid.
fn slide_fine_free(checker: &crate::collision::SceneChecker, a: &[f64], b: &[f64]) -> bool {
    (0..=2000).all(|i| {
        let t = f64::from(i) / 2000.0;
        checker.is_valid(&[a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])])
    })
}

#[test]
fn padded_shortcuts_shorten_a_detour_and_every_edge_stays_free() {
    use crate::collision::{Geometry, Obstacle};
    use nalgebra::{Isometry3, Vector3};
    use rand::SeedableRng;
    // a 10 cm cube at the origin; the path climbs over it on a wide detour
    let cube = Obstacle::new(
        "cube",
        Isometry3::identity(),
        Geometry::Box {
            half_extents: Vector3::repeat(0.05),
        },
    );
    let checker = slide_checker(cube);
    let detour = [-0.3, 0.0, -0.3, 0.4, 0.0, 0.45, 0.3, 0.4, 0.3, 0.0];
    let length = |p: &[f64]| -> f64 {
        p.windows(4)
            .step_by(2)
            .map(|w| ((w[2] - w[0]).powi(2) + (w[3] - w[1]).powi(2)).sqrt())
            .sum()
    };
    let clock = super::clock::Clock {
        start: Instant::now(),
        deadline: Deadline::none(),
    };
    for seed in 0..5 {
        let mut path = detour.to_vec();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        rrt_connect::shortcut(&checker, &mut path, 2, 0.05, 100, &mut rng, &clock);
        assert_eq!(
            (&path[..2], &path[path.len() - 2..]),
            (&detour[..2], &detour[8..])
        );
        // the straight line is 0.6 long and blocked; going over the cube's
        // corners at the sphere's clearance is about 0.66; the detour 2.12
        assert!(
            length(&path) < 0.8,
            "seed {seed}: {path:?} is {} long",
            length(&path)
        );
        for w in path.windows(4).step_by(2) {
            assert!(
                slide_fine_free(&checker, &w[..2], &w[2..]),
                "seed {seed}: edge {w:?} collides"
            );
        }
    }
}

#[test]
fn a_refused_motion_is_replaced_through_a_nudged_waypoint_proved_free() {
    use crate::collision::{Geometry, Obstacle};
    use nalgebra::{Isometry3, Vector3};
    use rand::SeedableRng;
    // A 2 cm sphere on an x–y slide and a 2 cm cube at the origin on its
    // straight way from x = −0.1 to x = 0.1.
    let checker_with = slide_checker;
    let cube = Obstacle::new(
        "cube",
        Isometry3::identity(),
        Geometry::Box {
            half_extents: Vector3::repeat(0.01),
        },
    );
    let checker = checker_with(cube);
    let (x, y) = ([-0.1, 0.0], [0.1, 0.0]);
    let bounds = [(-0.5, 0.5), (-0.5, 0.5)];
    assert!(!checker.motion_valid(&x, &y));
    let fine_free = |a: &[f64], b: &[f64]| slide_fine_free(&checker, a, b);
    let clock = super::clock::Clock {
        start: Instant::now(),
        deadline: Deadline::none(),
    };
    for seed in 0..5 {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let m = rrt_connect::nudged_waypoint(&checker, &bounds, &x, &y, 0.5, 0.05, &mut rng, &clock)
            .expect("a nudge around a 2 cm cube");
        // clear of the cube by the sphere's radius: |m_y| > 0.03 at least
        assert!(m[1].abs() > 0.03 && m[0].abs() < 0.5, "seed {seed}: {m:?}");
        assert!(fine_free(&x, &m) && fine_free(&m, &y), "seed {seed}: {m:?}");
    }
    // a wall across the whole slide: no nudge gets through
    let wall = Obstacle::new(
        "wall",
        Isometry3::identity(),
        Geometry::Box {
            half_extents: Vector3::new(0.01, 1.0, 1.0),
        },
    );
    let checker = checker_with(wall);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    assert_eq!(
        rrt_connect::nudged_waypoint(&checker, &bounds, &x, &y, 0.5, 0.05, &mut rng, &clock),
        None
    );
    // and a caller that asks to stop gets no waypoint, even around the cube
    let checker = checker_with(Obstacle::new(
        "cube",
        Isometry3::identity(),
        Geometry::Box {
            half_extents: Vector3::repeat(0.01),
        },
    ));
    let stopped = super::clock::Clock {
        deadline: Deadline::none().with_cancel(&|| true),
        ..clock
    };
    assert_eq!(
        rrt_connect::nudged_waypoint(&checker, &bounds, &x, &y, 0.5, 0.05, &mut rng, &stopped),
        None
    );
}

/// Regression: a CCSTOMP trajectory that was collision-free but outside its
/// tolerances came back as NO_VALID_TRAJECTORY with `valid` true. Over every
/// status a plan can end with (the exhaustive match fails to compile when a
/// status is added), `valid` holds exactly when it succeeded.
#[test]
fn valid_and_the_status_never_contradict_each_other() {
    let mut seen = Vec::new();
    let mut record = |r: PlanResult| {
        assert_eq!(
            r.valid,
            r.status == PlanStatus::Succeeded,
            "{:?} with valid = {}",
            r.status,
            r.valid
        );
        seen.push(r.status);
    };
    // succeeded, and collision-free but outside a 1 µm tube
    let (chain, w, mut req, _) = ur5_ccstomp_request();
    req.stomp.initial = InitialTrajectory::CartesianLine;
    record(plan(&chain, &w, &req, PlanControl::default()).unwrap());
    req.stomp.initial = InitialTrajectory::StraightLine;
    req.stomp.max_iterations = 1;
    req.cartesian.translation_tolerance = 1e-6;
    req.cartesian.rotation_tolerance = 1e-6;
    let r = plan(&chain, &w, &req, PlanControl::default()).unwrap();
    assert!(r.violates_tolerance);
    record(r);
    // invalid start and goal, a deadline, a cancellation
    let planar = planar3();
    let world = PlanarWorld::planar3_blocked();
    let mut req = blocked_request(Algorithm::Stomp);
    req.start = vec![0.0, 0.0, 0.0];
    record(plan(&planar, &world, &req, PlanControl::default()).unwrap());
    let mut req = blocked_request(Algorithm::RrtConnect);
    req.goal = Goal::Joints(vec![0.0, 0.0, 0.0]);
    record(plan(&planar, &world, &req, PlanControl::default()).unwrap());
    let mut req = blocked_request(Algorithm::Stomp);
    req.stomp.initial = InitialTrajectory::StraightLine;
    let past = PlanControl {
        deadline: Deadline::at(Instant::now()),
        ..Default::default()
    };
    record(plan(&planar, &world, &req, past).unwrap());
    let stop = || true;
    let cancelled = PlanControl {
        deadline: Deadline::none().with_cancel(&stop),
        ..Default::default()
    };
    record(plan(&planar, &world, &req, cancelled).unwrap());
    // a pose goal 5 m from a 1 m arm: unreachable
    let mut req = blocked_request(Algorithm::Ccstomp);
    req.goal = Goal::Pose(nalgebra::Isometry3::translation(5.0, 0.0, 0.0));
    req.goal_ik.max_restarts = 3;
    record(plan(&planar, &world, &req, PlanControl::default()).unwrap());
    // the detour problem, solved, and not solved in a 1 mm tube (the box sits
    // on the line)
    let (kr, boxed, start, goal) = kr210_box_on_the_line();
    let mut req = PlanRequest {
        start,
        goal: Goal::Joints(goal),
        algorithm: Algorithm::Ccstomp,
        ..Default::default()
    };
    req.stomp.timesteps = 10;
    record(plan(&kr, &boxed, &req, PlanControl::default()).unwrap());
    req.cartesian.translation_tolerance = 1e-3;
    req.stomp.max_iterations = 2;
    let r = plan(&kr, &boxed, &req, PlanControl::default()).unwrap();
    assert_eq!(r.status, PlanStatus::NoValidTrajectory);
    // no valid trajectory after the first pass: a second, finer pass ran on
    // from its best, and the cost never rose across the two
    assert_eq!(r.iterations, 4);
    assert_eq!(r.cost_history.len(), 5);
    assert!(
        r.cost_history.windows(2).all(|c| c[1] <= c[0]),
        "{:?}",
        r.cost_history
    );
    record(r);
    seen.sort_by_key(|s| format!("{s:?}"));
    seen.dedup();
    // every status there is
    let all = [
        PlanStatus::Succeeded,
        PlanStatus::NoValidTrajectory,
        PlanStatus::InvalidStart,
        PlanStatus::InvalidGoal,
        PlanStatus::GoalUnreachable,
        PlanStatus::Timeout,
        PlanStatus::Cancelled,
    ];
    for s in all {
        // a new status must be added here (and reached above)
        match s {
            PlanStatus::Succeeded
            | PlanStatus::NoValidTrajectory
            | PlanStatus::InvalidStart
            | PlanStatus::InvalidGoal
            | PlanStatus::GoalUnreachable
            | PlanStatus::Timeout
            | PlanStatus::Cancelled => assert!(seen.contains(&s), "{s:?} not reached: {seen:?}"),
        }
    }
}

/// Largest deviation of the waypoints from the straight tool line between
/// the first and last waypoint, recomputed here with 4×4 matrices:
/// `PL(s)` (lerp, quaternion slerp), `Diff = PL⁻¹·FK(q)`, e_t = ‖t(Diff)‖,
/// e_r = acos((tr R(Diff) − 1)/2).
fn worst_deviation_by_matrices(chain: &Chain, q: &[f64]) -> (f64, f64) {
    let dof = chain.dof();
    let n = q.len() / dof;
    let (a, b) = (chain.fk(&q[..dof]), chain.fk(&q[(n - 1) * dof..]));
    let (mut wt, mut wr) = (0.0_f64, 0.0_f64);
    for (i, row) in q.chunks_exact(dof).enumerate() {
        let s = i as f64 / (n - 1) as f64;
        let p = a.translation.vector * (1.0 - s) + b.translation.vector * s;
        let pl = nalgebra::Isometry3::from_parts(p.into(), a.rotation.slerp(&b.rotation, s)).to_homogeneous();
        let diff = pl.try_inverse().unwrap() * chain.fk(row).to_homogeneous();
        wt = wt.max(diff.fixed_view::<3, 1>(0, 3).norm());
        let tr = diff.fixed_view::<3, 3>(0, 0).trace();
        wr = wr.max(((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos());
    }
    (wt, wr)
}

/// The KR 210 turning its base from −40° to +40° (tool 2.1 m along y) with a
/// 0.3 m box centred on the midpoint of the straight tool line: the checker
/// and the start and goal joints.
fn kr210_box_on_the_line() -> (
    std::sync::Arc<Chain>,
    crate::collision::SceneChecker,
    Vec<f64>,
    Vec<f64>,
) {
    use crate::collision::{
        AcmParams, AllowedCollisions, CheckerParams, Geometry, Obstacle, RobotModel, Scene, SceneChecker,
        SceneGeometry, SceneLimits,
    };
    let chain = builtin_chain("kuka_kr210_r2700_extra").unwrap();
    let deg = f64::to_radians;
    let start = vec![deg(-40.0), deg(-85.0), deg(95.0), 0.0, deg(80.0), 0.0];
    let mut goal = start.clone();
    goal[0] = deg(40.0);
    let (a, b) = (chain.fk(&start), chain.fk(&goal));
    let mid = (a.translation.vector + b.translation.vector) / 2.0;
    let model = std::sync::Arc::new(RobotModel::new(chain.clone()).unwrap());
    // MoveIt's setup-assistant matrix: the KR 210's capsules of non-adjacent
    // links overlap in every state near the wrist
    let acm = AllowedCollisions::sampled(&model, &AcmParams::default()).unwrap();
    let cube = Obstacle::new(
        "box",
        nalgebra::Isometry3::translation(mid.x, mid.y, mid.z),
        Geometry::Box {
            half_extents: nalgebra::Vector3::repeat(0.15),
        },
    );
    let scene = Scene::new(vec![cube], &SceneLimits::default()).unwrap();
    let world = std::sync::Arc::new(SceneGeometry::build(&scene).unwrap());
    let checker = SceneChecker::new(model, &acm, world, CheckerParams::default()).unwrap();
    (chain, checker, start, goal)
}

/// Regression: with a box on the straight tool line CCSTOMP started from an
/// RRT-Connect path that turned the tool 0.2–0.4 rad off the slerped
/// orientation and returned NO_VALID_TRAJECTORY for most seeds. It now
/// starts from a detour inside the tube and succeeds for every seed, at S0's
/// 10 waypoints and at the default 40.
#[test]
fn ccstomp_detours_around_a_box_on_the_straight_tool_line() {
    let (chain, checker, start, goal) = kr210_box_on_the_line();
    // hand-derived: A1 turns about −z, so the tool goes from +y to −y at the
    // same x and z, 2·r·sin 40° apart with r = |x / cos 40°|
    let (a, b) = (
        chain.fk(&start).translation.vector,
        chain.fk(&goal).translation.vector,
    );
    let r = a.x / 40f64.to_radians().cos();
    assert!((a.y - r * 40f64.to_radians().sin()).abs() < 1e-9 && (a.y + b.y).abs() < 1e-9);
    assert!(((a - b).norm() - 2.09).abs() < 0.01, "{}", (a - b).norm());
    // the tool's straight line runs through the box: its midpoint collides
    // whatever the arm does, so any valid answer leaves the line
    for n in [10, 40] {
        for seed in 0..3 {
            let mut req = PlanRequest {
                start: start.clone(),
                goal: Goal::Joints(goal.clone()),
                algorithm: Algorithm::Ccstomp,
                seed,
                ..Default::default()
            };
            req.stomp.timesteps = n;
            let r = plan(&chain, &checker, &req, PlanControl::default()).unwrap();
            assert_eq!(r.status, PlanStatus::Succeeded, "n {n} seed {seed}");
            assert_ends(&r, &start, &goal);
            let (wt, wr) = worst_deviation_by_matrices(&chain, &r.q);
            assert!(wt <= 1.0 && wr <= 0.2, "n {n} seed {seed}: {wt} m, {wr} rad");
            // the box's half edge plus the smallest link radius off the line
            assert!(wt > 0.15, "n {n} seed {seed}: only {wt} m off the line");
            for (d, (t, rot)) in r
                .deviation
                .iter()
                .zip(r.q.chunks_exact(6).enumerate().map(|(i, q)| {
                    let s = i as f64 / (n - 1) as f64;
                    let pl = super::CartesianLine::between(&chain, &start, &goal).pose_at(s);
                    let diff = pl.to_homogeneous().try_inverse().unwrap() * chain.fk(q).to_homogeneous();
                    let tr = diff.fixed_view::<3, 3>(0, 0).trace();
                    (
                        diff.fixed_view::<3, 1>(0, 3).norm(),
                        ((tr - 1.0) / 2.0).clamp(-1.0, 1.0).acos(),
                    )
                }))
            {
                assert!((d.translation - t).abs() < 1e-9 && (d.rotation - rot).abs() < 1e-6);
            }
            // every state at 0.01 rad along every segment is free
            assert!(fine_valid(&checker, &r.q, 6, 0.01), "n {n} seed {seed}");
        }
    }
}

/// The detour search asks the checker about each state once: a candidate's
/// waypoints are checked while it is solved, not again with its motions.
#[test]
fn the_detour_search_checks_each_state_once() {
    use std::collections::HashMap;
    use std::sync::Mutex;
    let (chain, checker, start, goal) = kr210_box_on_the_line();
    // the scene checker behind a counter of the exact states it is asked about
    // (interpolated motions, so every query is a state)
    struct Counting<'a> {
        inner: &'a crate::collision::SceneChecker,
        seen: Mutex<HashMap<Vec<u64>, usize>>,
    }
    impl StateChecker for Counting<'_> {
        fn dof(&self) -> usize {
            self.inner.dof()
        }
        fn is_valid(&self, q: &[f64]) -> bool {
            let key = q.iter().map(|v| v.to_bits()).collect();
            *self.seen.lock().unwrap().entry(key).or_default() += 1;
            self.inner.is_valid(q)
        }
        fn clearance(&self, q: &[f64], d: f64) -> f64 {
            self.inner.clearance(q, d)
        }
    }
    let counting = Counting {
        inner: &checker,
        seen: Mutex::new(HashMap::new()),
    };
    let clock = super::clock::Clock {
        start: Instant::now(),
        deadline: Deadline::none(),
    };
    let tube = CartesianParams::default();
    let n = 20;
    let q = super::detour::tube_start(&chain, &counting, &start, &goal, n, Some(&tube), &clock)
        .expect("a detour around the box");
    let seen = counting.seen.lock().unwrap();
    // the straight line collides, so at least one detour was solved: its
    // waypoints were asked about, once each
    for row in q.chunks_exact(6).skip(1).take(n - 2) {
        let key: Vec<u64> = row.iter().map(|v| v.to_bits()).collect();
        assert_eq!(seen.get(&key), Some(&1), "{row:?}");
    }
    let twice: Vec<_> = seen.iter().filter(|(_, c)| **c > 1).collect();
    assert!(
        twice.is_empty(),
        "{} states asked about more than once",
        twice.len()
    );
    // neither end is asked about again
    for end in [&start, &goal] {
        let key: Vec<u64> = end.iter().map(|v| v.to_bits()).collect();
        assert_eq!(seen.get(&key), None);
    }
}

/// The ladder graph alone, on the planar 3-link arm: the tool moves 0.6 m
/// along y at x = 0.6 m pointing along +x, through a 5 cm circle at
/// (0.6, 0). Only a detour towards the base (−x) clears it (towards +x the
/// last link still crosses the circle); the ladder finds one inside a
/// 0.3 m tube at the line's orientation.
#[test]
fn the_ladder_graph_finds_the_one_side_that_clears_the_circle() {
    use crate::ik::{IkParams, IkTarget, solve_ik};
    use nalgebra::Isometry3;
    let chain = planar3();
    let mut w = PlanarWorld::planar3_blocked();
    w.circles = vec![(0.6, 0.0, 0.05)];
    let joints_at = |y: f64| {
        let p = IkParams {
            num_solutions: 4,
            ..IkParams::default()
        };
        let r = solve_ik(
            &chain,
            &IkTarget::Pose(Isometry3::translation(0.6, y, 0.0)),
            None,
            &p,
            3,
            Deadline::none(),
        )
        .unwrap();
        // the elbow-up branch (second joint positive) for both ends
        r.solutions
            .iter()
            .find(|s| s.joints[1] > 0.0)
            .unwrap()
            .joints
            .clone()
    };
    let (start, goal) = (joints_at(-0.3), joints_at(0.3));
    assert!(w.is_valid(&start) && w.is_valid(&goal));
    let line = CartesianLine::between(&chain, &start, &goal);
    let clock = super::clock::Clock {
        start: Instant::now(),
        deadline: Deadline::none(),
    };
    let ik = IkParams {
        max_restarts: 0,
        ..IkParams::default()
    };
    let mut solver = crate::ik::IkSolver::new(&chain);
    let n = 20;
    let q = super::ladder::ladder_path(&mut solver, &w, &line, 0.3, &start, &goal, n, &ik, 0.5, &clock)
        .expect("a chain around the circle");
    assert_eq!(
        (&q[..3], &q[q.len() - 3..]),
        (&start[..], &goal[..]),
        "ends not kept exactly"
    );
    assert!(
        fine_valid(&w.shrunk(0.01), &q, 3, 0.001),
        "independent check found a collision"
    );
    let (wt, wr) = worst_deviation_by_matrices(&chain, &q);
    assert!(wt <= 0.3 && wr < 1e-4, "{wt} m, {wr} rad");
    // the tool passes the circle on the base's side (x < 0.6); the last link
    // points along +x, so its tip is its point nearest the circle's centre and
    // stays beyond the radius plus the link's (0.05 + 0.02 m)
    let tips: Vec<_> = q
        .chunks_exact(3)
        .map(|r| chain.fk(r).translation.vector)
        .collect();
    assert!(tips.iter().all(|p| p.x < 0.6 + 1e-6), "{tips:?}");
    assert!(
        tips.iter()
            .filter(|p| p.y.abs() < 0.07)
            .all(|p| (p.x - 0.6).hypot(p.y) > 0.07),
        "{tips:?}"
    );
    assert!(tips.iter().any(|p| p.x < 0.53), "{tips:?}");
    // cancelled: no chain
    let cancelled = std::sync::atomic::AtomicBool::new(true);
    let stopped = super::clock::Clock {
        deadline: Deadline::none().with_cancel(&cancelled),
        ..clock
    };
    assert!(
        super::ladder::ladder_path(&mut solver, &w, &line, 0.3, &start, &goal, n, &ik, 0.5, &stopped)
            .is_none()
    );
}

/// The detour search and the second pass look at the deadline: CCSTOMP on the
/// blocked-line problem with a budget far below what the plan takes answers
/// soon after it, as a timeout or a success.
#[test]
fn ccstomp_on_a_blocked_line_answers_by_its_deadline() {
    let (chain, checker, start, goal) = kr210_box_on_the_line();
    for budget_ms in [0, 2] {
        let mut req = PlanRequest {
            start: start.clone(),
            goal: Goal::Joints(goal.clone()),
            algorithm: Algorithm::Ccstomp,
            ..Default::default()
        };
        // a 1 mm tube: no detour fits, so the search runs through the ladder
        req.cartesian.translation_tolerance = 1e-3;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let t0 = Instant::now();
        let r = pool.install(|| {
            let ctl = PlanControl {
                deadline: Deadline::at(t0 + Duration::from_millis(budget_ms)),
                ..Default::default()
            };
            plan(&chain, &checker, &req, ctl).unwrap()
        });
        let took = t0.elapsed();
        // the margin is for a loaded CI host (one IK solve or state check
        // past the deadline at most, then timing and scoring)
        assert!(
            took < Duration::from_millis(budget_ms + 150),
            "{budget_ms} ms: {took:?}"
        );
        assert_eq!(r.status, PlanStatus::Timeout, "{budget_ms} ms");
        assert!(!r.valid);
    }
}

/// Regression: a MotionBenchMaker box problem (no. 5, read by `mbm_data`;
/// fingers held at 40 mm) planned with padded motions and shortcuts came back
/// NO_VALID_TRAJECTORY: the final re-check proved each edge again on pieces
/// of its own, and a piece of a proved edge can fail a proof of its own
/// (the pads differ) though every state of it is free. The plan succeeds,
/// and every edge is free at a 0.01 rad re-check.
#[test]
fn a_padded_rrt_connect_plan_with_shortcuts_is_valid_on_a_motionbenchmaker_box() {
    use crate::collision::{
        AcmParams, AllowedCollisions, CheckerParams, RobotModel, SceneChecker, SceneGeometry, SceneLimits,
        attached_bodies, parse_joint_request, parse_planning_scene,
    };
    use crate::robot::builtin_urdf;
    use std::sync::Arc;
    let chain = builtin_chain("franka_panda_hand").unwrap();
    let fingers = [("panda_finger_joint1", 0.04), ("panda_finger_joint2", 0.04)];
    let attached = attached_bodies(builtin_urdf("franka_panda_hand").unwrap(), &chain, &fingers).unwrap();
    let model = Arc::new(RobotModel::with_parts(chain.clone(), &attached, &[]).unwrap());
    let acm = AllowedCollisions::sampled(&model, &AcmParams::default()).unwrap();
    let Some(dir) = crate::mbm_data::problems() else {
        return;
    };
    let (scene, request) = crate::mbm_data::problem(&dir, "box", 5);
    let scene = parse_planning_scene(&scene, &SceneLimits::default()).unwrap();
    let world = Arc::new(SceneGeometry::build(&scene).unwrap());
    let params = CheckerParams {
        padded_motion: true,
        ..CheckerParams::default()
    };
    let checker = SceneChecker::new(model, &acm, world, params).unwrap();
    let joints = parse_joint_request(&request).unwrap();
    let arm = |state: &[(String, f64)]| -> Vec<f64> {
        (1..=7)
            .map(|i| {
                state
                    .iter()
                    .find(|(n, _)| *n == format!("panda_joint{i}"))
                    .unwrap()
                    .1
            })
            .collect()
    };
    let (start, goal) = (arm(&joints.start), arm(&joints.goal));
    let request = PlanRequest {
        start: start.clone(),
        goal: Goal::Joints(goal.clone()),
        algorithm: Algorithm::RrtConnect,
        seed: 5,
        ..Default::default()
    };
    let r = plan(&chain, &checker, &request, PlanControl::default()).unwrap();
    assert_eq!((r.status, r.valid), (PlanStatus::Succeeded, true));
    assert_ends(&r, &start, &goal);
    for w in r.q.chunks_exact(7).collect::<Vec<_>>().windows(2) {
        let span = w[0]
            .iter()
            .zip(w[1])
            .map(|(a, b)| (b - a).abs())
            .fold(0.0, f64::max);
        let steps = (span / 0.01).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let q: Vec<f64> = w[0].iter().zip(w[1]).map(|(a, b)| a + t * (b - a)).collect();
            assert!(checker.is_valid(&q), "state {q:?} of edge {w:?} collides");
        }
    }
}
