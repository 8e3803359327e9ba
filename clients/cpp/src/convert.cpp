#include "convert.hpp"

namespace kinplan::convert {

void to_proto(const Eigen::Isometry3d& T, pb::Pose* out) {
  const Eigen::Vector3d p = T.translation();
  const Eigen::Quaterniond q(T.linear());
  auto* position = out->mutable_position();
  position->set_x(p.x());
  position->set_y(p.y());
  position->set_z(p.z());
  auto* orientation = out->mutable_orientation();
  orientation->set_x(q.x());
  orientation->set_y(q.y());
  orientation->set_z(q.z());
  orientation->set_w(q.w());
}

Eigen::Isometry3d from_proto(const pb::Pose& pose) {
  const auto& o = pose.orientation();
  Eigen::Quaterniond q(o.w(), o.x(), o.y(), o.z());
  // proto3: an unset (all-zero) quaternion is the identity
  if (o.x() == 0 && o.y() == 0 && o.z() == 0 && o.w() == 0) q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() << pose.position().x(), pose.position().y(), pose.position().z();
  return T;
}

void to_proto(const Eigen::VectorXd& v, google::protobuf::RepeatedField<double>* out) {
  out->Resize(static_cast<int>(v.size()), 0.0);
  for (Eigen::Index i = 0; i < v.size(); ++i) out->Set(static_cast<int>(i), v[i]);
}

Eigen::VectorXd from_proto(const google::protobuf::RepeatedField<double>& v) {
  Eigen::VectorXd out(v.size());
  for (int i = 0; i < v.size(); ++i) out[i] = v.Get(i);
  return out;
}

void to_proto(const Eigen::MatrixXd& m, pb::Matrix* out) {
  out->set_rows(static_cast<uint32_t>(m.rows()));
  out->set_cols(static_cast<uint32_t>(m.cols()));
  auto* data = out->mutable_data();
  data->Resize(static_cast<int>(m.size()), 0.0);
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) data->Set(static_cast<int>(r * m.cols() + c), m(r, c));
}

Eigen::MatrixXd from_proto(const pb::Matrix& m) {
  const auto rows = static_cast<Eigen::Index>(m.rows());
  const auto cols = static_cast<Eigen::Index>(m.cols());
  if (static_cast<Eigen::Index>(m.data_size()) != rows * cols) {
    throw Error(grpc::StatusCode::INTERNAL, "matrix reply: data size does not match rows x cols");
  }
  Eigen::MatrixXd out(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c) out(r, c) = m.data(static_cast<int>(r * cols + c));
  return out;
}

namespace {

pb::IkMethod method_to_proto(IkMethod m) {
  switch (m) {
    case IkMethod::JacobianInverse: return pb::IK_METHOD_JACOBIAN_INVERSE;
    case IkMethod::Newton: return pb::IK_METHOD_NEWTON;
    case IkMethod::Ccd: return pb::IK_METHOD_CCD;
    case IkMethod::Fabrik: return pb::IK_METHOD_FABRIK;
    case IkMethod::LengthRelaxation: return pb::IK_METHOD_LENGTH_RELAXATION;
    case IkMethod::Analytic: return pb::IK_METHOD_ANALYTIC;
    case IkMethod::LevenbergMarquardt: break;
  }
  return pb::IK_METHOD_LEVENBERG_MARQUARDT;
}

IkStatus status_from_proto(pb::IkStatus s) {
  switch (s) {
    case pb::IK_STATUS_CONVERGED: return IkStatus::Converged;
    case pb::IK_STATUS_MAX_ITERATIONS: return IkStatus::MaxIterations;
    case pb::IK_STATUS_STALLED: return IkStatus::Stalled;
    case pb::IK_STATUS_TIME_BUDGET: return IkStatus::TimeBudget;
    case pb::IK_STATUS_CANCELLED: return IkStatus::Cancelled;
    default: return IkStatus::Unspecified;
  }
}

PlanStatus plan_status_from_proto(pb::PlanStatus s) {
  switch (s) {
    case pb::PLAN_STATUS_SUCCEEDED: return PlanStatus::Succeeded;
    case pb::PLAN_STATUS_NO_VALID_TRAJECTORY: return PlanStatus::NoValidTrajectory;
    case pb::PLAN_STATUS_INVALID_START: return PlanStatus::InvalidStart;
    case pb::PLAN_STATUS_INVALID_GOAL: return PlanStatus::InvalidGoal;
    case pb::PLAN_STATUS_TIMEOUT: return PlanStatus::Timeout;
    case pb::PLAN_STATUS_CANCELLED: return PlanStatus::Cancelled;
    case pb::PLAN_STATUS_GOAL_UNREACHABLE: return PlanStatus::GoalUnreachable;
    default: return PlanStatus::Unspecified;
  }
}

}  // namespace

void to_proto(const IkOptions& o, pb::IkOptions* out) {
  out->set_method(method_to_proto(o.method));
  if (o.position_tolerance) out->set_position_tolerance(*o.position_tolerance);
  if (o.orientation_tolerance) out->set_orientation_tolerance(*o.orientation_tolerance);
  out->set_position_only(o.position_only);
  out->set_max_iterations(o.max_iterations);
  if (o.max_restarts) out->set_max_restarts(*o.max_restarts);
  out->set_num_solutions(o.num_solutions);
  out->set_rng_seed(o.rng_seed);
  if (o.time_budget) out->set_time_budget(*o.time_budget);
  out->set_joint_limits(o.clamp_to_limits ? pb::JOINT_LIMIT_MODE_CLAMP
                                          : pb::JOINT_LIMIT_MODE_IGNORE);
}

IkResult from_proto(const pb::SolveIkResponse& r) {
  IkResult out;
  out.success = r.success();
  out.status = status_from_proto(r.status());
  out.iterations = static_cast<uint32_t>(r.total_iterations());
  out.server_elapsed_us = r.elapsed_us();
  for (const auto& s : r.solutions()) out.solutions.push_back(from_proto(s.joints()));
  const pb::IkSolution& first = r.solutions_size() > 0 ? r.solutions(0) : r.best_attempt();
  out.joints = from_proto(first.joints());
  out.position_error = first.position_error();
  out.orientation_error = first.orientation_error();
  return out;
}

void to_proto(const Scene& scene, pb::Scene* out) {
  for (const Obstacle& o : scene) {
    pb::CollisionObject* c = out->add_objects();
    c->set_id(o.id);
    to_proto(o.pose, c->mutable_pose());
    switch (o.shape) {
      case Obstacle::Shape::Box: {
        auto* size = c->mutable_box()->mutable_size();
        size->set_x(o.size.x());
        size->set_y(o.size.y());
        size->set_z(o.size.z());
        break;
      }
      case Obstacle::Shape::Sphere: c->mutable_sphere()->set_radius(o.radius); break;
      case Obstacle::Shape::Cylinder:
        c->mutable_cylinder()->set_radius(o.radius);
        c->mutable_cylinder()->set_length(o.length);
        break;
    }
  }
}

void to_proto(const PlanOptions& o, pb::PlanRequest* out) {
  switch (o.algorithm) {
    case PlanAlgorithm::RrtConnect: out->set_algorithm(pb::PLAN_ALGORITHM_RRT_CONNECT); break;
    case PlanAlgorithm::Stomp: out->set_algorithm(pb::PLAN_ALGORITHM_STOMP); break;
    case PlanAlgorithm::Ccstomp: out->set_algorithm(pb::PLAN_ALGORITHM_CCSTOMP); break;
  }
  out->set_seed(o.seed);
  if (o.time_budget) out->mutable_options()->set_time_budget(*o.time_budget);
  if (o.motion_resolution) out->mutable_options()->set_motion_resolution(*o.motion_resolution);
}

PlanResult from_proto(const pb::PlanResponse& r) {
  PlanResult out;
  out.status = plan_status_from_proto(r.status());
  out.message = r.message();
  out.valid = r.valid();
  out.duration = r.duration();
  for (const auto& p : r.trajectory().points()) {
    out.positions.push_back(from_proto(p.positions()));
    out.times.push_back(p.time_from_start());
  }
  out.colliding.assign(r.colliding().begin(), r.colliding().end());
  return out;
}

RobotInfo from_proto(const pb::DescribeRobotResponse& r) {
  RobotInfo out;
  out.name = r.name();
  const int n = r.joints_size();
  out.lower.resize(n);
  out.upper.resize(n);
  for (int i = 0; i < n; ++i) {
    out.joint_names.push_back(r.joints(i).name());
    out.lower[i] = r.joints(i).lower();
    out.upper[i] = r.joints(i).upper();
  }
  return out;
}

}  // namespace kinplan::convert
