// kinplan::Client, Robot and IkStream over the generated gRPC stubs.
#include "kinplan/client.hpp"

#include <mutex>
#include <type_traits>
#include <utility>

#include <grpcpp/grpcpp.h>

#include "convert.hpp"
#include "kinplan/v1/kinematics.grpc.pb.h"
#include "kinplan/v1/planning.grpc.pb.h"
#include "kinplan/v1/robot.grpc.pb.h"

namespace kinplan {

namespace pb = ::kinplan::v1;

// ---------------------------------------------------------------- Error

Error::Error(grpc::StatusCode code, std::string details)
    : std::runtime_error(std::string(code_name(code)) + ": " + details),
      code_(code),
      details_(std::move(details)) {}

const char* Error::code_name(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK: return "OK";
    case grpc::StatusCode::CANCELLED: return "CANCELLED";
    case grpc::StatusCode::UNKNOWN: return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED: return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND: return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS: return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED: return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED: return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION: return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED: return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE: return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED: return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL: return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE: return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS: return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED: return "UNAUTHENTICATED";
    default: return "UNKNOWN";
  }
}

namespace {

Error error_of(const grpc::Status& s) { return Error(s.error_code(), s.error_message()); }

// Longer than this counts as no deadline (and would overflow the clock).
constexpr double kLongestDeadlineSeconds = 1e8;

}  // namespace

// ---------------------------------------------------------------- Client

struct Client::Impl {
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<pb::RobotService::Stub> robots;
  std::unique_ptr<pb::KinematicsService::Stub> kinematics;
  std::unique_ptr<pb::PlanningService::Stub> planning;
  Duration timeout;

  void set_deadline(grpc::ClientContext& ctx, const Timeout& t) const {
    const Duration d = t ? *t : timeout;
    if (d.count() >= kLongestDeadlineSeconds) return;
    ctx.set_deadline(std::chrono::system_clock::now() +
                     std::chrono::duration_cast<std::chrono::system_clock::duration>(d));
  }
};

Client::Client(const std::string& address, ClientOptions options) : impl_(std::make_shared<Impl>()) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(options.max_message_bytes);
  args.SetMaxSendMessageSize(options.max_message_bytes);
  impl_->channel = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
  impl_->robots = pb::RobotService::NewStub(impl_->channel);
  impl_->kinematics = pb::KinematicsService::NewStub(impl_->channel);
  impl_->planning = pb::PlanningService::NewStub(impl_->channel);
  impl_->timeout = options.timeout;
}

Client::~Client() = default;

void Client::wait_for_ready(Duration timeout) {
  const auto deadline = std::chrono::system_clock::now() +
                        std::chrono::duration_cast<std::chrono::system_clock::duration>(timeout);
  if (!impl_->channel->WaitForConnected(deadline)) {
    throw Error(grpc::StatusCode::UNAVAILABLE, "no server answered within the timeout");
  }
}

// ---------------------------------------------------------------- Robot

/// What a robot reference holds: a built-in name, or URDF text and the model
/// id the server returned for it (shared by copies of the Robot).
struct Robot::State {
  bool is_urdf = false;
  std::string name_or_urdf, base_link, tip_link;
  mutable std::mutex mutex;
  std::string model_id;

  /// Fills `ref`; true when it names the cached model id instead of the text.
  bool fill(pb::RobotRef* ref, bool force_inline) const {
    ref->set_base_link(base_link);
    ref->set_tip_link(tip_link);
    if (!is_urdf) {
      ref->set_name(name_or_urdf);
      return false;
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (!model_id.empty() && !force_inline) {
      ref->set_model_id(model_id);
      return true;
    }
    ref->set_urdf(name_or_urdf);
    return false;
  }
  void remember(const std::string& id) {
    if (!is_urdf || id.empty()) return;
    std::lock_guard<std::mutex> lock(mutex);
    model_id = id;
  }
  void forget() {
    std::lock_guard<std::mutex> lock(mutex);
    model_id.clear();
  }
};

Robot::Robot(std::shared_ptr<Client::Impl> client, std::shared_ptr<State> state)
    : client_(std::move(client)), state_(std::move(state)) {}

Robot Client::robot(const std::string& name, const std::string& base_link,
                    const std::string& tip_link) {
  auto s = std::make_shared<Robot::State>();
  s->name_or_urdf = name;
  s->base_link = base_link;
  s->tip_link = tip_link;
  return Robot(impl_, std::move(s));
}

Robot Client::robot_from_urdf(const std::string& urdf, const std::string& base_link,
                              const std::string& tip_link) {
  if (urdf.find('<') == std::string::npos) {
    throw Error(grpc::StatusCode::INVALID_ARGUMENT,
                "urdf: expected the URDF document's text, got no XML (a file path? read the "
                "file first)");
  }
  auto s = std::make_shared<Robot::State>();
  s->is_urdf = true;
  s->name_or_urdf = urdf;
  s->base_link = base_link;
  s->tip_link = tip_link;
  return Robot(impl_, std::move(s));
}

std::string Robot::model_id() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  return state_->model_id;
}

namespace {

template <class T, class = void>
struct has_model_id : std::false_type {};
template <class T>
struct has_model_id<T, std::void_t<decltype(std::declval<const T&>().model_id())>>
    : std::true_type {};

/// One unary call about a robot: the cached model id when there is one; on
/// NOT_FOUND for it, the same request again once with the URDF text.
template <class Resp, class Req, class Rpc>
Resp call(const Client::Impl& client, Robot::State& robot, Req request, Rpc rpc,
          const Timeout& timeout) {
  const bool by_id = robot.fill(request.mutable_robot(), false);
  Resp reply;
  grpc::Status status;
  {
    grpc::ClientContext ctx;
    client.set_deadline(ctx, timeout);
    status = rpc(&ctx, request, &reply);
  }
  if (status.error_code() == grpc::StatusCode::NOT_FOUND && by_id) {
    robot.forget();
    robot.fill(request.mutable_robot(), true);
    reply.Clear();
    grpc::ClientContext ctx;
    client.set_deadline(ctx, timeout);
    status = rpc(&ctx, request, &reply);
  }
  if (!status.ok()) throw error_of(status);
  if constexpr (has_model_id<Resp>::value) robot.remember(reply.model_id());
  return reply;
}

}  // namespace

RobotInfo Robot::describe(Timeout timeout) const {
  auto reply = call<pb::DescribeRobotResponse>(
      *client_, *state_, pb::DescribeRobotRequest(),
      [&](grpc::ClientContext* c, const pb::DescribeRobotRequest& r, pb::DescribeRobotResponse* o) {
        return client_->robots->DescribeRobot(c, r, o);
      },
      timeout);
  return convert::from_proto(reply);
}

Eigen::Isometry3d Robot::fk(const Eigen::VectorXd& q, Timeout timeout) const {
  pb::ForwardKinematicsRequest request;
  convert::to_proto(q, request.mutable_joint_positions());
  auto reply = call<pb::ForwardKinematicsResponse>(
      *client_, *state_, std::move(request),
      [&](grpc::ClientContext* c, const pb::ForwardKinematicsRequest& r,
          pb::ForwardKinematicsResponse* o) { return client_->robots->ForwardKinematics(c, r, o); },
      timeout);
  return convert::from_proto(reply.tool_pose());
}

std::vector<Eigen::Isometry3d> Robot::fk_batch(const Eigen::MatrixXd& qs, Timeout timeout) const {
  pb::ForwardKinematicsBatchRequest request;
  convert::to_proto(qs, request.mutable_joint_positions());
  auto reply = call<pb::ForwardKinematicsBatchResponse>(
      *client_, *state_, std::move(request),
      [&](grpc::ClientContext* c, const pb::ForwardKinematicsBatchRequest& r,
          pb::ForwardKinematicsBatchResponse* o) {
        return client_->robots->ForwardKinematicsBatch(c, r, o);
      },
      timeout);
  const Eigen::MatrixXd rows = convert::from_proto(reply.tool_poses());  // x y z qx qy qz qw
  std::vector<Eigen::Isometry3d> out;
  out.reserve(static_cast<size_t>(rows.rows()));
  for (Eigen::Index i = 0; i < rows.rows(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(rows(i, 6), rows(i, 3), rows(i, 4), rows(i, 5))
                     .normalized()
                     .toRotationMatrix();
    T.translation() = rows.row(i).head<3>().transpose();
    out.push_back(T);
  }
  return out;
}

Eigen::MatrixXd Robot::jacobian(const Eigen::VectorXd& q, Timeout timeout) const {
  pb::JacobianRequest request;
  convert::to_proto(q, request.mutable_joint_positions());
  auto reply = call<pb::JacobianResponse>(
      *client_, *state_, std::move(request),
      [&](grpc::ClientContext* c, const pb::JacobianRequest& r, pb::JacobianResponse* o) {
        return client_->robots->Jacobian(c, r, o);
      },
      timeout);
  return convert::from_proto(reply.jacobian());
}

IkResult Robot::ik(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed,
                   const IkOptions& options, Timeout timeout) const {
  pb::SolveIkRequest request;
  convert::to_proto(target, request.mutable_target());
  convert::to_proto(seed, request.mutable_seed());
  convert::to_proto(options, request.mutable_options());
  auto reply = call<pb::SolveIkResponse>(
      *client_, *state_, std::move(request),
      [&](grpc::ClientContext* c, const pb::SolveIkRequest& r, pb::SolveIkResponse* o) {
        return client_->kinematics->SolveIk(c, r, o);
      },
      timeout);
  return convert::from_proto(reply);
}

namespace {

PlanResult plan_call(const Client::Impl& client, Robot::State& robot, pb::PlanRequest request,
                     const Eigen::VectorXd& start, const Scene& scene, const PlanOptions& options,
                     const Timeout& timeout) {
  convert::to_proto(start, request.mutable_start());
  convert::to_proto(scene, request.mutable_scene());
  convert::to_proto(options, &request);
  auto reply = call<pb::PlanResponse>(
      client, robot, std::move(request),
      [&](grpc::ClientContext* c, const pb::PlanRequest& r, pb::PlanResponse* o) {
        return client.planning->Plan(c, r, o);
      },
      timeout);
  return convert::from_proto(reply);
}

}  // namespace

PlanResult Robot::plan(const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                       const Scene& scene, const PlanOptions& options, Timeout timeout) const {
  pb::PlanRequest request;
  convert::to_proto(goal, request.mutable_goal_joints()->mutable_positions());
  return plan_call(*client_, *state_, std::move(request), start, scene, options, timeout);
}

PlanResult Robot::plan(const Eigen::VectorXd& start, const Eigen::Isometry3d& goal,
                       const Scene& scene, const PlanOptions& options, Timeout timeout) const {
  pb::PlanRequest request;
  convert::to_proto(goal, request.mutable_goal_pose());
  return plan_call(*client_, *state_, std::move(request), start, scene, options, timeout);
}

// ---------------------------------------------------------------- Obstacle

Obstacle Obstacle::box(std::string id, const Eigen::Isometry3d& pose, const Eigen::Vector3d& size) {
  Obstacle o;
  o.id = std::move(id);
  o.shape = Shape::Box;
  o.pose = pose;
  o.size = size;
  return o;
}

Obstacle Obstacle::sphere(std::string id, const Eigen::Vector3d& centre, double radius) {
  Obstacle o;
  o.id = std::move(id);
  o.shape = Shape::Sphere;
  o.pose = Eigen::Isometry3d(Eigen::Translation3d(centre));
  o.radius = radius;
  return o;
}

Obstacle Obstacle::cylinder(std::string id, const Eigen::Isometry3d& pose, double radius,
                            double length) {
  Obstacle o;
  o.id = std::move(id);
  o.shape = Shape::Cylinder;
  o.pose = pose;
  o.radius = radius;
  o.length = length;
  return o;
}

// ---------------------------------------------------------------- IkStream

struct IkStream::Impl {
  std::shared_ptr<Client::Impl> client;  // keeps the channel alive
  std::shared_ptr<Robot::State> robot;
  grpc::ClientContext ctx;
  std::unique_ptr<grpc::ClientReaderWriter<pb::StreamIkRequest, pb::StreamIkResponse>> stream;
  pb::StreamIkRequest first;  // robot, options and seed of the first message
  bool first_pending = true;
  bool finished = false;
  uint64_t sequence = 0;
  // reused across cycles: no allocation per target once warm
  pb::StreamIkRequest message;
  pb::StreamIkResponse reply;

  /// Reads what is left, then the call's final status.
  grpc::Status finish() {
    finished = true;
    while (stream->Read(&reply)) {
    }
    return stream->Finish();
  }
  [[noreturn]] void fail(const char* what) {
    const grpc::Status s = finish();
    if (!s.ok()) throw error_of(s);
    throw Error(grpc::StatusCode::INTERNAL, what);
  }
};

IkStream Robot::stream_ik(const IkOptions& options, const Eigen::VectorXd& seed,
                          Timeout timeout) const {
  auto impl = std::make_unique<IkStream::Impl>();
  impl->client = client_;
  impl->robot = state_;
  // the session's first message always carries the robot itself (an inline
  // URDF as text): nothing to resend in the middle of a stream
  state_->fill(impl->first.mutable_robot(), true);
  convert::to_proto(options, impl->first.mutable_options());
  convert::to_proto(seed, impl->first.mutable_seed());
  client_->set_deadline(impl->ctx, timeout);
  impl->stream = client_->kinematics->StreamIk(&impl->ctx);
  return IkStream(std::move(impl));
}

IkStream::IkStream(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
IkStream::IkStream(IkStream&&) noexcept = default;
IkStream& IkStream::operator=(IkStream&&) noexcept = default;

IkStream::~IkStream() {
  if (!impl_ || impl_->finished) return;
  impl_->ctx.TryCancel();
  impl_->finish();
}

uint64_t IkStream::send(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed) {
  Impl& s = *impl_;
  if (s.finished) throw Error(grpc::StatusCode::FAILED_PRECONDITION, "the stream is closed");
  pb::StreamIkRequest& m = s.first_pending ? s.first : s.message;
  m.set_sequence(++s.sequence);
  convert::to_proto(target, m.mutable_target());
  if (seed.size() > 0 || !s.first_pending) convert::to_proto(seed, m.mutable_seed());
  s.first_pending = false;
  if (!s.stream->Write(m)) s.fail("the server closed the stream");
  return s.sequence;
}

IkResult IkStream::read() {
  Impl& s = *impl_;
  if (s.finished) throw Error(grpc::StatusCode::FAILED_PRECONDITION, "the stream is closed");
  if (!s.stream->Read(&s.reply)) s.fail("the server ended the stream before answering");
  if (s.reply.sequence() == 1) s.robot->remember(s.reply.result().model_id());
  IkResult out = convert::from_proto(s.reply.result());
  out.sequence = s.reply.sequence();
  return out;
}

IkResult IkStream::solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed) {
  send(target, seed);
  return read();
}

void IkStream::close() {
  if (!impl_ || impl_->finished) return;
  impl_->stream->WritesDone();
  const grpc::Status s = impl_->finish();
  if (!s.ok()) throw error_of(s);
}

}  // namespace kinplan
