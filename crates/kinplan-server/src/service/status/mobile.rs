//! Mobile-room errors as `Status`: every [`MobileError`] becomes INVALID_ARGUMENT naming the
//! request field, and [`MobileField`] identifiers become proto field paths here and nowhere
//! else (`mobile.proto`: the chassis, follow options and obstacles nest their parameters one
//! message deeper than the domain's structs do).

use tonic::Status;

use super::invalid;
use kinplan_core::mobile::{
    AstarField, ChassisKind, Component, FollowField, MobileError, MobileField, ObstaclePart, SimField,
};

/// INVALID_ARGUMENT naming the request field that a [`MobileError`] is about; INTERNAL
/// ([`token_failure`]) for a state the server could not encode.
pub fn mobile_error(err: MobileError) -> Status {
    let field = match &err {
        MobileError::TokenEncoding { .. } => return token_failure(err),
        MobileError::NotFinite { field, .. }
        | MobileError::NotPositive { field, .. }
        | MobileError::OutOfRange { field, .. }
        | MobileError::TooFew { field, .. } => proto_path(*field),
        MobileError::EmptyPath => "path".into(),
        MobileError::BadToken { .. } => "state_token".into(),
        MobileError::StartInCollision { .. } => "start".into(),
        MobileError::WheelMismatch { .. } => "wheels".into(),
    };
    invalid(field, err.to_string())
}

/// A controller state the server could not encode: a server bug, never an
/// empty token the client would take for a fresh start.
fn token_failure(err: MobileError) -> Status {
    tracing::error!(%err, "a controller state could not be encoded");
    Status::internal("the controller state could not be encoded")
}

/// The proto field path of a domain field. Parameter leaves keep their domain names (the
/// proto messages name their fields as the domain's parameter structs do); the structure
/// around them is the proto's.
pub fn proto_path(field: MobileField) -> String {
    match field {
        MobileField::Chassis { kind, param } => {
            let kind = match kind {
                ChassisKind::Tricycle => "tricycle",
                ChassisKind::Car => "car",
                ChassisKind::Omni => "omni",
                ChassisKind::Differential => "differential",
            };
            format!("chassis.{kind}.{}", param.name())
        }
        // The wheel state's oneof case is not part of the path clients have always seen.
        MobileField::Wheel(w) => format!("wheels.{}", w.name()),
        MobileField::Twist(c) => format!("twist.{}", component(c)),
        MobileField::Command(c) => format!("command.{}", component(c)),
        MobileField::State(c) => format!("state.{}", component(c)),
        MobileField::Start(c) => format!("start.{}", component(c)),
        MobileField::Goal(c) => format!("goal.{}", component(c)),
        MobileField::Path { index, part } => format!("path[{index}].{}", component(part)),
        MobileField::Obstacle { index, part } => match part {
            ObstaclePart::Center(c) => format!("world[{index}].circle.center.{}", component(c)),
            ObstaclePart::Radius => format!("world[{index}].circle.radius"),
            ObstaclePart::Vertices => format!("world[{index}].polygon.vertices"),
            ObstaclePart::Vertex { index: v, part } => {
                format!("world[{index}].polygon.vertices[{v}].{}", component(part))
            }
        },
        MobileField::Follow(f) => match f {
            FollowField::Own(p) => format!("follow.{}", p.name()),
            FollowField::Lyapunov(p) => format!("follow.lyapunov.{}", p.name()),
            FollowField::PurePursuit(p) => format!("follow.pure_pursuit.{}", p.name()),
            FollowField::Steering(p) => format!("follow.steering.{}", p.name()),
        },
        // The step count is max_time / dt: the request sets it through max_time.
        MobileField::Sim(SimField::Steps) => "sim.max_time".into(),
        MobileField::Sim(p) => format!("sim.{}", p.name()),
        // Not a proto path (the grid size follows from the world, resolution and padding),
        // but the name clients have always seen.
        MobileField::Astar(AstarField::GridCells) => "astar grid cells".into(),
        MobileField::Astar(p) => format!("astar.{}", p.name()),
        MobileField::Vdf(p) => format!("vdf.{}", p.name()),
        MobileField::Sensors(p) => format!("sensors.{}", p.name()),
        MobileField::Readings => "readings".into(),
        MobileField::Reading(i) => format!("readings[{i}]"),
        MobileField::Dt => "dt".into(),
        MobileField::RobotRadius => "robot_radius".into(),
    }
}

fn component(c: Component) -> &'static str {
    match c {
        Component::X => "x",
        Component::Y => "y",
        Component::Theta => "theta",
        Component::Vx => "vx",
        Component::Vy => "vy",
        Component::Omega => "omega",
        Component::Heading => "heading",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinplan_core::mobile::{
        ChassisParam, FollowParam, LyapunovParam, PurePursuitParam, SensorField, SteeringParam, VdfField,
        WheelField,
    };

    /// The request fields clients see, written out by hand from `mobile.proto`.
    #[test]
    fn domain_fields_become_request_fields() {
        let cases = [
            (
                MobileField::Chassis {
                    kind: ChassisKind::Omni,
                    param: ChassisParam::WheelRadius,
                },
                "chassis.omni.wheel_radius",
            ),
            (
                MobileField::Chassis {
                    kind: ChassisKind::Car,
                    param: ChassisParam::MaxSteer,
                },
                "chassis.car.max_steer",
            ),
            (
                MobileField::Follow(FollowField::Lyapunov(LyapunovParam::Gamma)),
                "follow.lyapunov.gamma",
            ),
            (
                MobileField::Follow(FollowField::PurePursuit(PurePursuitParam::RotateYawRate)),
                "follow.pure_pursuit.rotate_yaw_rate",
            ),
            (
                MobileField::Follow(FollowField::Steering(SteeringParam::Candidates)),
                "follow.steering.candidates",
            ),
            (
                MobileField::Follow(FollowField::Own(FollowParam::HeadingTolerance)),
                "follow.heading_tolerance",
            ),
            (MobileField::Sim(SimField::Steps), "sim.max_time"),
            (MobileField::Sim(SimField::Dt), "sim.dt"),
            (MobileField::State(Component::X), "state.x"),
            (MobileField::Start(Component::Theta), "start.theta"),
            (MobileField::Goal(Component::Y), "goal.y"),
            (MobileField::Twist(Component::Omega), "twist.omega"),
            (
                MobileField::Obstacle {
                    index: 3,
                    part: ObstaclePart::Radius,
                },
                "world[3].circle.radius",
            ),
            (
                MobileField::Obstacle {
                    index: 3,
                    part: ObstaclePart::Center(Component::X),
                },
                "world[3].circle.center.x",
            ),
            (
                MobileField::Obstacle {
                    index: 2,
                    part: ObstaclePart::Vertex {
                        index: 1,
                        part: Component::Y,
                    },
                },
                "world[2].polygon.vertices[1].y",
            ),
            (
                MobileField::Obstacle {
                    index: 0,
                    part: ObstaclePart::Vertices,
                },
                "world[0].polygon.vertices",
            ),
            (MobileField::Vdf(VdfField::SafeDistance), "vdf.safe_distance"),
            (
                MobileField::Sensors(SensorField::RaysPerBeam),
                "sensors.rays_per_beam",
            ),
            (MobileField::Astar(AstarField::Resolution), "astar.resolution"),
            (MobileField::Astar(AstarField::GridCells), "astar grid cells"),
            (
                MobileField::Path {
                    index: 4,
                    part: Component::Heading,
                },
                "path[4].heading",
            ),
            (MobileField::Wheel(WheelField::Speeds), "wheels.speeds"),
            (MobileField::Reading(5), "readings[5]"),
            (MobileField::Readings, "readings"),
            (MobileField::Dt, "dt"),
            (MobileField::RobotRadius, "robot_radius"),
        ];
        for (field, path) in cases {
            assert_eq!(proto_path(field), path, "{field:?}");
        }
    }
}
