//! Motion planning in joint space: STOMP and the Cartesian-constrained
//! CCSTOMP of S0 §3, RRT-Connect with shortcutting, time parameterisation,
//! and [`plan`], the one entry point a service calls. Planners see the world
//! only through [`StateChecker`](crate::collision::StateChecker).

mod cartesian;
mod clock;
mod column_scan;
mod costs;
mod detour;
mod entry;
mod error;
mod initial;
mod kd_index;
mod ladder;
pub(crate) mod noise;
mod params;
mod rrt_connect;
mod rrt_tree;
mod stomp;
mod stomp_matrices;
mod timing;

pub use cartesian::{CartesianLine, Deviation, cartesian_cost, deviation, perturb_pose, violates};
pub use entry::{Algorithm, Goal, PlanControl, PlanRequest, PlanResult, PlanStatus, Timings, plan};
pub use error::{PlanError, PlanField};
pub use params::{CartesianParams, InitialTrajectory, RrtParams, StompParams};
pub use rrt_connect::{RrtOutcome, RrtStop, rrt_connect};
pub use stomp::{IterationReport, StompOutcome, StompStop};
pub use stomp_matrices::{
    ACCELERATION_STENCIL, MatricesError, PADDING, StompMatrices, finite_difference_matrix,
};
pub use timing::{
    BlendedPath, Curve, MAX_GRID_POINTS, MAX_SAMPLE_VALUES, MIN_SEGMENT_TIME, SCurve, SpeedProfile,
    TimedTrajectory, TimingMethod, TimingParams, ToppError, retime, time_parameterize, topp_ra,
    waypoint_rates,
};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod toy;
