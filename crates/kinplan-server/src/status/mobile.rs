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
/// (`token_failure`) for a state the server could not encode.
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

    /// Walks a field path (`a.b[3].c`) through the proto's message descriptors from `root`.
    fn resolves(set: &prost_types::FileDescriptorSet, root: &str, path: &str) -> bool {
        let messages: std::collections::HashMap<String, &prost_types::DescriptorProto> = set
            .file
            .iter()
            .flat_map(|f| {
                let package = f.package().to_string();
                f.message_type
                    .iter()
                    .map(move |m| (format!(".{package}.{}", m.name()), m))
            })
            .collect();
        let mut message = messages.get(root).copied();
        for segment in path.split('.') {
            let name = segment.split('[').next().unwrap_or(segment);
            let Some(m) = message else { return false };
            let Some(field) = m.field.iter().find(|f| f.name() == name) else {
                return false;
            };
            message = messages.get(field.type_name()).copied();
        }
        true
    }

    /// Every proto path the mapping produces names a real field of one of the mobile requests
    /// (read from the compiled descriptor set), except the two names clients have always seen
    /// that are not paths: `wheels.<value>` (the proto nests the value under the chassis kind)
    /// and `astar grid cells`.
    #[test]
    fn every_mapped_path_exists_in_the_proto() {
        use prost::Message;
        let set = prost_types::FileDescriptorSet::decode(crate::pb::FILE_DESCRIPTOR_SET).unwrap();
        let roots = [
            ".kinplan.v1.WheelKinematicsRequest",
            ".kinplan.v1.ControlStepRequest",
            ".kinplan.v1.FollowPathRequest",
            ".kinplan.v1.NavigateRequest",
        ];
        use ChassisParam as P;
        let chassis = [
            (
                ChassisKind::Tricycle,
                &[P::Wheelbase, P::WheelRadius, P::MaxSpeed, P::MaxSteer][..],
            ),
            (
                ChassisKind::Car,
                &[P::Wheelbase, P::Track, P::WheelRadius, P::MaxSpeed, P::MaxSteer],
            ),
            (
                ChassisKind::Omni,
                &[
                    P::WheelRadius,
                    P::CenterDistance,
                    P::MaxWheelSpeed,
                    P::FirstWheelAngle,
                ],
            ),
            (
                ChassisKind::Differential,
                &[P::WheelRadius, P::Track, P::MaxWheelSpeed],
            ),
        ];
        let mut fields: Vec<MobileField> = chassis
            .iter()
            .flat_map(|(kind, params)| {
                params
                    .iter()
                    .map(|&param| MobileField::Chassis { kind: *kind, param })
            })
            .collect();
        let xy = [Component::X, Component::Y];
        let pose = [Component::X, Component::Y, Component::Theta];
        fields.extend(pose.map(MobileField::State));
        fields.extend(pose.map(MobileField::Start));
        fields.extend(xy.map(MobileField::Goal));
        fields.extend([Component::Vx, Component::Vy, Component::Omega].map(MobileField::Twist));
        fields.extend(
            [Component::X, Component::Y, Component::Heading].map(|part| MobileField::Path { index: 2, part }),
        );
        fields.extend(xy.map(|c| MobileField::Obstacle {
            index: 1,
            part: ObstaclePart::Center(c),
        }));
        fields.extend(xy.map(|part| MobileField::Obstacle {
            index: 1,
            part: ObstaclePart::Vertex { index: 2, part },
        }));
        fields.extend(
            [ObstaclePart::Radius, ObstaclePart::Vertices]
                .map(|part| MobileField::Obstacle { index: 0, part }),
        );
        fields.extend(
            FollowParam::ALL
                .iter()
                .map(|&p| MobileField::Follow(FollowField::Own(p))),
        );
        fields.extend(
            LyapunovParam::ALL
                .iter()
                .map(|&p| MobileField::Follow(FollowField::Lyapunov(p))),
        );
        fields.extend(
            PurePursuitParam::ALL
                .iter()
                .map(|&p| MobileField::Follow(FollowField::PurePursuit(p))),
        );
        fields.extend(
            SteeringParam::ALL
                .iter()
                .map(|&p| MobileField::Follow(FollowField::Steering(p))),
        );
        fields.extend(SimField::ALL.iter().map(|&p| MobileField::Sim(p)));
        fields.extend(VdfField::ALL.iter().map(|&p| MobileField::Vdf(p)));
        fields.extend(SensorField::ALL.iter().map(|&p| MobileField::Sensors(p)));
        fields.extend(AstarField::ALL.iter().map(|&p| MobileField::Astar(p)));
        fields.extend([
            MobileField::Readings,
            MobileField::Reading(3),
            MobileField::Dt,
            MobileField::RobotRadius,
        ]);
        let mut missing = Vec::new();
        for field in fields {
            let path = proto_path(field);
            if field == MobileField::Astar(AstarField::GridCells) {
                continue;
            }
            if !roots.iter().any(|root| resolves(&set, root, &path)) {
                missing.push(path);
            }
        }
        assert!(missing.is_empty(), "{missing:?}");
        // The wheel values are one level short of a path.
        for w in WheelField::ALL {
            assert!(!resolves(&set, roots[0], &proto_path(MobileField::Wheel(*w))));
        }
    }
}
