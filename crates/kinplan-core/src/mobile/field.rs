//! Typed identifiers of the inputs a [`MobileError`](super::MobileError) is about.
//!
//! The domain names an offending input by its place in the domain's own values (which pose,
//! which obstacle and vertex, which parameter of which parameter set); it never writes a
//! wire-format field path. A service maps these identifiers to its own field names (the gRPC
//! server does so in one module). `Display` gives the domain's dotted name, e.g.
//! `world[3].vertices[1].y` or `vdf.safe_distance`.

use std::fmt;

/// Defines a field-less enum of parameter names with `name()` (the parameter's name in the
/// domain struct) and `ALL` (every variant, for exhaustive tests).
macro_rules! parameter_names {
    ($(#[$meta:meta])* $enum:ident { $($(#[$vmeta:meta])* $variant:ident => $name:literal,)+ }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $enum {
            $($(#[$vmeta])* $variant,)+
        }

        impl $enum {
            /// Every variant.
            pub const ALL: &[$enum] = &[$($enum::$variant,)+];

            /// The parameter's name in the domain's parameter struct.
            pub fn name(self) -> &'static str {
                match self {
                    $($enum::$variant => $name,)+
                }
            }
        }

        impl fmt::Display for $enum {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

parameter_names! {
    /// A component of a point, pose, twist or path node.
    Component {
        /// x, m.
        X => "x",
        /// y, m.
        Y => "y",
        /// Heading θ of a pose, rad.
        Theta => "theta",
        /// Forward speed of a twist.
        Vx => "vx",
        /// Lateral speed of a twist.
        Vy => "vy",
        /// Yaw rate of a twist.
        Omega => "omega",
        /// Arrival heading of a path node.
        Heading => "heading",
    }
}

parameter_names! {
    /// The kind of chassis a parameter belongs to.
    ChassisKind {
        /// [`TricycleParams`](super::TricycleParams).
        Tricycle => "tricycle",
        /// [`CarParams`](super::CarParams).
        Car => "car",
        /// [`OmniParams`](super::OmniParams).
        Omni => "omni",
        /// [`DifferentialParams`](super::DifferentialParams).
        Differential => "differential",
    }
}

parameter_names! {
    /// A chassis dimension or limit.
    ChassisParam {
        /// Wheelbase L.
        Wheelbase => "wheelbase",
        /// Track width.
        Track => "track",
        /// Wheel radius r.
        WheelRadius => "wheel_radius",
        /// Speed limit.
        MaxSpeed => "max_speed",
        /// Steering limit.
        MaxSteer => "max_steer",
        /// Wheel-to-centre distance R of the omni base.
        CenterDistance => "center_distance",
        /// Wheel speed limit.
        MaxWheelSpeed => "max_wheel_speed",
        /// Angle of the omni base's first wheel.
        FirstWheelAngle => "first_wheel_angle",
    }
}

parameter_names! {
    /// A value of a [`WheelState`](super::WheelState).
    WheelField {
        /// Tricycle drive speed.
        Speed => "speed",
        /// Tricycle steering angle.
        Steer => "steer",
        /// Car rear-left wheel speed.
        RearLeft => "rear_left",
        /// Car rear-right wheel speed.
        RearRight => "rear_right",
        /// Car front-left steering angle.
        SteerLeft => "steer_left",
        /// Car front-right steering angle.
        SteerRight => "steer_right",
        /// Omni wheel speeds.
        Speeds => "speeds",
        /// Differential left wheel speed.
        Left => "left",
        /// Differential right wheel speed.
        Right => "right",
    }
}

parameter_names! {
    /// A field of [`PathFollowParams`](super::PathFollowParams) itself.
    FollowParam {
        /// Switching distance.
        SwitchingDistance => "switching_distance",
        /// Goal tolerance.
        GoalTolerance => "goal_tolerance",
        /// Heading tolerance.
        HeadingTolerance => "heading_tolerance",
    }
}

parameter_names! {
    /// A field of [`LyapunovParams`](super::LyapunovParams).
    LyapunovParam {
        /// γ.
        Gamma => "gamma",
        /// k.
        K => "k",
        /// h.
        H => "h",
        /// λ.
        Lambda => "lambda",
        /// Speed limit.
        MaxSpeed => "max_speed",
        /// Yaw-rate limit.
        MaxYawRate => "max_yaw_rate",
    }
}

parameter_names! {
    /// A field of [`PurePursuitParams`](super::PurePursuitParams).
    PurePursuitParam {
        /// Lookahead distance.
        Lookahead => "lookahead",
        /// Desired speed.
        DesiredSpeed => "desired_speed",
        /// Approach distance.
        ApproachDistance => "approach_distance",
        /// Minimum approach speed.
        MinApproachSpeed => "min_approach_speed",
        /// Smallest heading error that turns in place.
        RotateMinAngle => "rotate_min_angle",
        /// Yaw rate of turning in place.
        RotateYawRate => "rotate_yaw_rate",
    }
}

parameter_names! {
    /// A field of [`SteeringParams`](super::SteeringParams).
    SteeringParam {
        /// Speed.
        Speed => "speed",
        /// Wheelbase.
        Wheelbase => "wheelbase",
        /// Steering limit.
        MaxSteer => "max_steer",
        /// ε.
        Epsilon => "epsilon",
        /// Candidate count.
        Candidates => "candidates",
    }
}

/// A path-follower parameter: of the follower itself or of one of its controllers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FollowField {
    /// Of [`PathFollowParams`](super::PathFollowParams).
    Own(FollowParam),
    /// Of its Lyapunov gains.
    Lyapunov(LyapunovParam),
    /// Of its pure-pursuit parameters.
    PurePursuit(PurePursuitParam),
    /// Of its goal-seeking / shortest-path parameters.
    Steering(SteeringParam),
}

parameter_names! {
    /// A field of [`SimParams`](super::SimParams), or the step count they imply.
    SimField {
        /// Robot disc radius.
        RobotRadius => "robot_radius",
        /// Control period.
        Dt => "dt",
        /// Time limit.
        MaxTime => "max_time",
        /// The step count `max_time / dt`.
        Steps => "max_time / dt",
    }
}

parameter_names! {
    /// A field of [`GridAstarParams`](super::GridAstarParams), or the grid size they imply.
    AstarField {
        /// Cell size.
        Resolution => "resolution",
        /// Obstacle inflation.
        Inflation => "inflation",
        /// Grid padding.
        Padding => "padding",
        /// Largest grid.
        MaxCells => "max_cells",
        /// The cell count a world needs at this resolution.
        GridCells => "grid cells",
    }
}

parameter_names! {
    /// A field of [`VdfParams`](super::VdfParams).
    VdfField {
        /// d_sa.
        SafeDistance => "safe_distance",
        /// K.
        Magnitude => "magnitude",
        /// Weight decay.
        WeightDecay => "weight_decay",
        /// Turning-side gain.
        TurnGain => "turn_gain",
        /// Release distance.
        ReleaseDistance => "release_distance",
        /// Speed limit.
        MaxSpeed => "max_speed",
        /// Yaw-rate limit.
        MaxYawRate => "max_yaw_rate",
        /// Heading gain.
        HeadingGain => "heading_gain",
        /// Slow-down distance.
        SlowDistance => "slow_distance",
        /// n.
        ProgressSteps => "progress_steps",
        /// c1.
        ProgressMin => "progress_min",
        /// m.
        NoPathSteps => "no_path_steps",
        /// c2.
        NoPathMin => "no_path_min",
        /// Leave tolerance.
        LeaveTolerance => "leave_tolerance",
        /// Hit radius.
        HitRadius => "hit_radius",
        /// Wall gain.
        WallGain => "wall_gain",
        /// Goal tolerance.
        GoalTolerance => "goal_tolerance",
    }
}

parameter_names! {
    /// A field of [`RangeSensorParams`](super::RangeSensorParams).
    SensorField {
        /// Sensor count.
        Count => "count",
        /// Rays per beam.
        RaysPerBeam => "rays_per_beam",
        /// Largest gap.
        MaxRange => "max_range",
        /// Beam opening angle.
        BeamWidth => "beam_width",
        /// Noise standard deviation.
        NoiseSigma => "noise_sigma",
    }
}

/// The part of an obstacle a value belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObstaclePart {
    /// A component of a circle's centre.
    Center(Component),
    /// A circle's radius.
    Radius,
    /// A polygon's vertex list as a whole (its length).
    Vertices,
    /// A component of a polygon's vertex.
    Vertex {
        /// Index of the vertex in the polygon.
        index: usize,
        /// x or y.
        part: Component,
    },
}

/// An input of a mobile-robot function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MobileField {
    /// A chassis dimension or limit.
    Chassis {
        /// The chassis kind.
        kind: ChassisKind,
        /// The parameter.
        param: ChassisParam,
    },
    /// A wheel speed or steering angle.
    Wheel(WheelField),
    /// A component of a body twist to convert into wheel speeds.
    Twist(Component),
    /// A component of a command to integrate.
    Command(Component),
    /// A component of the robot's current pose.
    State(Component),
    /// A component of the start pose of a run.
    Start(Component),
    /// A component of the goal.
    Goal(Component),
    /// A component of a path node.
    Path {
        /// Index of the node in the path.
        index: usize,
        /// x, y or heading.
        part: Component,
    },
    /// A value of an obstacle of the world.
    Obstacle {
        /// Index of the obstacle in the world.
        index: usize,
        /// Which value.
        part: ObstaclePart,
    },
    /// A path-follower parameter.
    Follow(FollowField),
    /// A simulation setting.
    Sim(SimField),
    /// A grid A* setting.
    Astar(AstarField),
    /// A vector-distance navigator parameter.
    Vdf(VdfField),
    /// A sensor-ring parameter.
    Sensors(SensorField),
    /// The range readings as a whole (their count).
    Readings,
    /// One range reading.
    Reading(usize),
    /// The control period of one controller step.
    Dt,
    /// The robot radius used to sense a world for one controller step.
    RobotRadius,
}

impl fmt::Display for FollowField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FollowField::Own(p) => write!(f, "follow.{p}"),
            FollowField::Lyapunov(p) => write!(f, "lyapunov.{p}"),
            FollowField::PurePursuit(p) => write!(f, "pure_pursuit.{p}"),
            FollowField::Steering(p) => write!(f, "steering.{p}"),
        }
    }
}

impl fmt::Display for MobileField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MobileField::Chassis { kind, param } => write!(f, "{kind}.{param}"),
            MobileField::Wheel(w) => write!(f, "wheels.{w}"),
            MobileField::Twist(c) => write!(f, "twist.{c}"),
            MobileField::Command(c) => write!(f, "command.{c}"),
            MobileField::State(c) => write!(f, "state.{c}"),
            MobileField::Start(c) => write!(f, "start.{c}"),
            MobileField::Goal(c) => write!(f, "goal.{c}"),
            MobileField::Path { index, part } => write!(f, "path[{index}].{part}"),
            MobileField::Obstacle { index, part } => match part {
                ObstaclePart::Center(c) => write!(f, "world[{index}].center.{c}"),
                ObstaclePart::Radius => write!(f, "world[{index}].radius"),
                ObstaclePart::Vertices => write!(f, "world[{index}].vertices"),
                ObstaclePart::Vertex { index: v, part } => write!(f, "world[{index}].vertices[{v}].{part}"),
            },
            MobileField::Follow(p) => write!(f, "{p}"),
            MobileField::Sim(p) => write!(f, "sim.{p}"),
            MobileField::Astar(p) => write!(f, "astar.{p}"),
            MobileField::Vdf(p) => write!(f, "vdf.{p}"),
            MobileField::Sensors(p) => write!(f, "sensors.{p}"),
            MobileField::Readings => f.write_str("readings"),
            MobileField::Reading(i) => write!(f, "readings[{i}]"),
            MobileField::Dt => f.write_str("dt"),
            MobileField::RobotRadius => f.write_str("robot_radius"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The domain's names, written out by hand.
    #[test]
    fn fields_display_as_dotted_domain_names() {
        let cases = [
            (
                MobileField::Chassis {
                    kind: ChassisKind::Omni,
                    param: ChassisParam::WheelRadius,
                },
                "omni.wheel_radius",
            ),
            (MobileField::State(Component::Theta), "state.theta"),
            (
                MobileField::Obstacle {
                    index: 2,
                    part: ObstaclePart::Vertex {
                        index: 1,
                        part: Component::Y,
                    },
                },
                "world[2].vertices[1].y",
            ),
            (
                MobileField::Path {
                    index: 4,
                    part: Component::Heading,
                },
                "path[4].heading",
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::Gamma)),
                "lyapunov.gamma",
            ),
            (MobileField::Sim(SimField::Steps), "sim.max_time / dt"),
            (MobileField::Reading(7), "readings[7]"),
        ];
        for (field, name) in cases {
            assert_eq!(field.to_string(), name);
        }
    }
}
