// kinplan C++ client: forward and inverse kinematics, Jacobians, a StreamIk
// session for control loops, and motion planning, over gRPC, with Eigen types.
//
//     kinplan::Client client("127.0.0.1:50051");
//     kinplan::Robot kr210 = client.robot("kuka_kr210_r2700_extra");
//     Eigen::Isometry3d T = kr210.fk(Eigen::VectorXd::Zero(6));
//     kinplan::IkResult r = kr210.ik(T, seed);
//
// Units: metres, radians (metres for prismatic joints), seconds. Poses are the
// tool (tip link) frame in the robot's base frame; joint vectors are in chain
// order (RobotService.DescribeRobot).
//
// Errors: every failed call throws kinplan::Error, which carries the gRPC
// status code (code()) and the server's message (details()), e.g.
// INVALID_ARGUMENT naming the bad field, NOT_FOUND for an unknown robot,
// DEADLINE_EXCEEDED when the call's deadline passed, UNAVAILABLE when no
// server answers. Results that are not errors stay in the result: an IK that
// did not converge (IkResult::success false) or a plan without a valid
// trajectory (PlanResult::status) is returned, not thrown.
//
// Deadlines: every call has one. The client's default (ClientOptions::timeout,
// 30 s) applies unless the call's `timeout` argument overrides it; pass
// kinplan::kNoDeadline for none. A StreamIk session's deadline covers the
// whole session.
//
// Robots sent as URDF text are sent once; later calls name the model by the
// content hash the server returned. If a server does not hold that model
// (NOT_FOUND, e.g. another replica or an evicted cache), the call is repeated
// once with the URDF text. Client and Robot may be used from several threads;
// an IkStream from one thread at a time.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <grpcpp/support/status.h>

namespace kinplan {

using Duration = std::chrono::duration<double>;
/// A call's deadline, relative to when it starts; unset: the client's default.
using Timeout = std::optional<Duration>;
/// Pass as a call's timeout for no deadline.
inline const Duration kNoDeadline = Duration::max();

/// A failed call: the gRPC status code and the server's message.
class Error : public std::runtime_error {
 public:
  Error(grpc::StatusCode code, std::string details);
  grpc::StatusCode code() const { return code_; }
  const std::string& details() const { return details_; }
  /// "INVALID_ARGUMENT", "NOT_FOUND", ...
  static const char* code_name(grpc::StatusCode code);

 private:
  grpc::StatusCode code_;
  std::string details_;
};

struct ClientOptions {
  /// Default deadline of every call.
  Duration timeout = std::chrono::seconds(30);
  /// Largest message sent or received, bytes (the server's default).
  int max_message_bytes = 16 * 1024 * 1024;
};

/// IK algorithm (kinematics.proto IkMethod).
enum class IkMethod { LevenbergMarquardt, JacobianInverse, Newton, Ccd, Fabrik, LengthRelaxation, Analytic };

/// The IK options that matter to most callers; unset ones take the server's
/// defaults (kinematics.proto IkOptions).
struct IkOptions {
  IkMethod method = IkMethod::LevenbergMarquardt;
  std::optional<double> position_tolerance;     ///< metres (default 1e-5)
  std::optional<double> orientation_tolerance;  ///< radians (default 1e-5)
  bool position_only = false;
  uint32_t max_iterations = 0;           ///< per attempt; 0: server default (100)
  std::optional<uint32_t> max_restarts;  ///< default 200 (SolveIk), 0 (StreamIk)
  uint32_t num_solutions = 0;            ///< 0: 1
  uint64_t rng_seed = 0;
  std::optional<double> time_budget;  ///< seconds; per target for StreamIk
  bool clamp_to_limits = true;        ///< false: limits ignored while iterating
};

enum class IkStatus { Unspecified, Converged, MaxIterations, Stalled, TimeBudget, Cancelled };

struct IkResult {
  /// At least one solution converged.
  bool success = false;
  /// The first (nearest to the seed) solution, or the best attempt when
  /// nothing converged.
  Eigen::VectorXd joints;
  /// Every converged solution, nearest to the seed first.
  std::vector<Eigen::VectorXd> solutions;
  double position_error = 0;     ///< of `joints`, metres
  double orientation_error = 0;  ///< of `joints`, radians
  uint32_t iterations = 0;       ///< all attempts
  IkStatus status = IkStatus::Unspecified;
  uint64_t server_elapsed_us = 0;  ///< solve time on the server
  uint64_t sequence = 0;           ///< StreamIk only: the target's number
};

/// An obstacle in the robot's base frame.
struct Obstacle {
  enum class Shape { Box, Sphere, Cylinder };
  std::string id;
  Shape shape = Shape::Box;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  ///< Box: full edge lengths
  double radius = 0;                               ///< Sphere, Cylinder
  double length = 0;                               ///< Cylinder, along its z

  static Obstacle box(std::string id, const Eigen::Isometry3d& pose, const Eigen::Vector3d& size);
  static Obstacle sphere(std::string id, const Eigen::Vector3d& centre, double radius);
  static Obstacle cylinder(std::string id, const Eigen::Isometry3d& pose, double radius,
                           double length);
};

using Scene = std::vector<Obstacle>;

enum class PlanAlgorithm { RrtConnect, Stomp, Ccstomp };

struct PlanOptions {
  PlanAlgorithm algorithm = PlanAlgorithm::RrtConnect;
  uint64_t seed = 0;                       ///< same request, same answer
  std::optional<double> time_budget;       ///< seconds
  std::optional<double> motion_resolution; ///< rad, (0, 0.05]
};

enum class PlanStatus {
  Unspecified, Succeeded, NoValidTrajectory, InvalidStart, InvalidGoal, Timeout, Cancelled,
  GoalUnreachable
};

struct PlanResult {
  PlanStatus status = PlanStatus::Unspecified;
  std::string message;
  bool valid = false;  ///< collision-free (checked at motion_resolution)
  /// Waypoints, start first, and their times from the start (seconds).
  std::vector<Eigen::VectorXd> positions;
  std::vector<double> times;
  double duration = 0;                 ///< seconds
  std::vector<std::string> colliding;  ///< "link:object" pairs for invalid start/goal
};

struct RobotInfo {
  std::string name;
  std::vector<std::string> joint_names;
  Eigen::VectorXd lower, upper;  ///< limits; +-inf when unlimited
  int dof() const { return static_cast<int>(joint_names.size()); }
};

class Robot;
class IkStream;

/// A connection to a kinplan server (one gRPC channel, insecure).
class Client {
 public:
  /// `address`: "host:port" or any gRPC target ("dns:///name:port").
  explicit Client(const std::string& address, ClientOptions options = {});
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Blocks until the channel is connected; throws Error(UNAVAILABLE) after `timeout`.
  void wait_for_ready(Duration timeout);
  /// A built-in robot by name ("ur5", "kuka_kr210_r2700_extra", ...).
  Robot robot(const std::string& name, const std::string& base_link = "",
              const std::string& tip_link = "");
  /// A robot sent as URDF text (the document, not a path).
  Robot robot_from_urdf(const std::string& urdf, const std::string& base_link = "",
                        const std::string& tip_link = "");

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

/// A robot on a server: a built-in name or a URDF with its cached model id.
/// Cheap to copy; copies share the model-id cache.
class Robot {
 public:
  RobotInfo describe(Timeout timeout = {}) const;
  /// Tool pose for joint vector q.
  Eigen::Isometry3d fk(const Eigen::VectorXd& q, Timeout timeout = {}) const;
  /// Tool poses of every row of qs (states x dof) in one call.
  std::vector<Eigen::Isometry3d> fk_batch(const Eigen::MatrixXd& qs, Timeout timeout = {}) const;
  /// 6 x n geometric Jacobian in the base frame: rows vx, vy, vz, wx, wy, wz.
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& q, Timeout timeout = {}) const;
  /// Joints that put the tool at `target`; empty seed: the middle of the limits.
  IkResult ik(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed = {},
              const IkOptions& options = {}, Timeout timeout = {}) const;
  /// Opens a StreamIk session; `seed` starts the first target (empty: the
  /// middle of the limits), each later one starts from the previous answer.
  IkStream stream_ik(const IkOptions& options = {}, const Eigen::VectorXd& seed = {},
                     Timeout timeout = {}) const;
  /// A collision-free timed trajectory from `start` to the joint goal.
  PlanResult plan(const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                  const Scene& scene = {}, const PlanOptions& options = {},
                  Timeout timeout = {}) const;
  /// ... or to a tool pose goal (IK picks the valid solution nearest the start).
  PlanResult plan(const Eigen::VectorXd& start, const Eigen::Isometry3d& goal,
                  const Scene& scene = {}, const PlanOptions& options = {},
                  Timeout timeout = {}) const;
  /// The model id the server returned for a URDF robot (empty until then, and
  /// always for built-ins).
  std::string model_id() const;

  struct State;

 private:
  friend class Client;
  Robot(std::shared_ptr<Client::Impl> client, std::shared_ptr<State> state);
  std::shared_ptr<Client::Impl> client_;
  std::shared_ptr<State> state_;
};

/// A StreamIk session: write a target, read its answer, in order. A control
/// loop calls solve() once per cycle (or send() then read() to overlap work).
/// A bad target ends the stream: the next read() throws Error naming the
/// field and the message's sequence number. close() (or the destructor) ends
/// the session.
class IkStream {
 public:
  IkStream(IkStream&&) noexcept;
  IkStream& operator=(IkStream&&) noexcept;
  ~IkStream();
  /// Writes a target (and optionally its own seed); returns its sequence number.
  uint64_t send(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed = {});
  /// Blocks for the next answer.
  IkResult read();
  /// send() then read().
  IkResult solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed = {});
  /// Ends the request side and waits for the server's status; throws Error if
  /// the stream failed. Idempotent.
  void close();

  struct Impl;

 private:
  friend class Robot;
  explicit IkStream(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace kinplan
