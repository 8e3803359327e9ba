// Eigen and client types <-> kinplan.v1 protobuf messages.
#pragma once

#include <Eigen/Geometry>

#include "kinplan/client.hpp"
#include "kinplan/v1/common.pb.h"
#include "kinplan/v1/kinematics.pb.h"
#include "kinplan/v1/planning.pb.h"
#include "kinplan/v1/robot.pb.h"

namespace kinplan::convert {

namespace pb = ::kinplan::v1;

/// Position and unit quaternion (x, y, z, w) of T; the quaternion is read from
/// T.linear() as given (a non-rotation is left for the server to refuse).
void to_proto(const Eigen::Isometry3d& T, pb::Pose* out);
Eigen::Isometry3d from_proto(const pb::Pose& pose);

void to_proto(const Eigen::VectorXd& v, google::protobuf::RepeatedField<double>* out);
Eigen::VectorXd from_proto(const google::protobuf::RepeatedField<double>& v);
/// Row-major rows x cols data.
void to_proto(const Eigen::MatrixXd& m, pb::Matrix* out);
Eigen::MatrixXd from_proto(const pb::Matrix& m);

void to_proto(const IkOptions& options, pb::IkOptions* out);
IkResult from_proto(const pb::SolveIkResponse& reply);

void to_proto(const Scene& scene, pb::Scene* out);
void to_proto(const PlanOptions& options, pb::PlanRequest* out);
PlanResult from_proto(const pb::PlanResponse& reply);

RobotInfo from_proto(const pb::DescribeRobotResponse& reply);

}  // namespace kinplan::convert
