//! kinplan: kinematics, inverse kinematics, trajectory scoring and mobile-robot
//! control, as a plain library (the domain core) and a gRPC service on top.

pub mod robot;
