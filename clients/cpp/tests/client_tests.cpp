// Tests of the C++ client against a real `kinplan serve` (started by ci.sh).
//
//     client_tests <address>
//
// Every expectation comes from an independent computation: hand-derived zero
// poses and a DH table written from the KR 210's published dimensions, round
// trips (FK of the IK answer), finite differences of FK, the plan's own start
// and goal, and the error codes the API documents. Started by ci.sh with
// --model-cache 1, so that alternating two URDF robots evicts each other's
// model and exercises the NOT_FOUND -> resend rule.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "kinplan/client.hpp"

namespace {

int failures = 0;

#define CHECK(cond)                                                                 \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "  FAILED %s:%d: %s\n", __FILE__, __LINE__, #cond);      \
      ++failures;                                                                   \
    }                                                                               \
  } while (0)

#define CHECK_NEAR(a, b, tol)                                                        \
  do {                                                                               \
    const double va = (a), vb = (b);                                                 \
    if (!(std::abs(va - vb) <= (tol))) {                                             \
      std::fprintf(stderr, "  FAILED %s:%d: %s = %.9g vs %s = %.9g (tol %g)\n",      \
                   __FILE__, __LINE__, #a, va, #b, vb, static_cast<double>(tol));    \
      ++failures;                                                                    \
    }                                                                                \
  } while (0)

using Eigen::Isometry3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
constexpr double kPi = 3.14159265358979323846;
const char* const kKr210 = "kuka_kr210_r2700_extra";

VectorXd vec(std::initializer_list<double> v) {
  VectorXd out(static_cast<Eigen::Index>(v.size()));
  Eigen::Index i = 0;
  for (double x : v) out[i++] = x;
  return out;
}

/// Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha).
Isometry3d dh(double theta, double d, double a, double alpha) {
  return Isometry3d(Eigen::AngleAxisd(theta, Vector3d::UnitZ())) * Eigen::Translation3d(0, 0, d) *
         Eigen::Translation3d(a, 0, 0) * Eigen::AngleAxisd(alpha, Vector3d::UnitX());
}

/// KR 210 R2700 extra from its data sheet (mm): A1 height 675, A1-A2 offset
/// 350, A2-A3 1150, A3-A4 offset 41, A3-wrist 1200, flange 215; the
/// controller's signs make A1, A4 and A6 turn about the negative DH axes.
Isometry3d kr210_dh(const VectorXd& q) {
  const double h = kPi / 2;
  return dh(-q[0], 0.675, 0.35, -h) * dh(q[1], 0, 1.15, 0) * dh(h + q[2], 0, 0.041, h) *
         dh(-q[3], 1.2, 0, -h) * dh(q[4], 0, 0, h) * dh(-q[5], 0.215, 0, 0);
}

double rotation_angle(const Isometry3d& a, const Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// ------------------------------------------------------------------ tests

void fk_matches_published_kinematics(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  // zero pose, by hand: arm stretched forward, 350 + 1150 + 1200 + 215 mm
  // out and 675 - 41 mm up
  const Isometry3d zero = kr210.fk(VectorXd::Zero(6));
  CHECK((zero.translation() - Vector3d(2.915, 0.0, 0.634)).norm() < 1e-9);
  CHECK(rotation_angle(zero, kr210_dh(VectorXd::Zero(6))) < 1e-9);
  // and a general pose against the DH table
  const VectorXd q = vec({0.3, -1.2, 1.0, 0.5, 0.7, -0.4});
  const Isometry3d T = kr210.fk(q);
  CHECK((T.translation() - kr210_dh(q).translation()).norm() < 1e-9);
  CHECK(rotation_angle(T, kr210_dh(q)) < 1e-9);
  // a batch gives the same poses as single calls
  Eigen::MatrixXd qs(2, 6);
  qs.row(0) = VectorXd::Zero(6).transpose();
  qs.row(1) = q.transpose();
  const std::vector<Isometry3d> batch = kr210.fk_batch(qs);
  CHECK(batch.size() == 2);
  CHECK((batch[1].translation() - kr210_dh(q).translation()).norm() < 1e-9);
  CHECK(rotation_angle(batch[1], kr210_dh(q)) < 1e-9);
  // UR5 zero pose in its DH base frame: x = a2 + a3, y = -(d4 + d6), z = d1 - d5
  const Isometry3d ur5 = c.robot("ur5").fk(VectorXd::Zero(6));
  CHECK((ur5.translation() - Vector3d(-0.425 - 0.39225, -(0.10915 + 0.0823),
                                      0.089159 - 0.09465)).norm() < 1e-9);
}

void ik_round_trip(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  const VectorXd q = vec({-0.4, -1.3, 1.4, 0.6, -0.9, 1.1});
  const Isometry3d target = kr210.fk(q);
  kinplan::IkOptions options;
  options.rng_seed = 7;
  const kinplan::IkResult r = kr210.ik(target, VectorXd(), options);
  CHECK(r.success);
  CHECK(r.status == kinplan::IkStatus::Converged);
  CHECK(r.joints.size() == 6);
  CHECK(r.position_error <= 1e-5);
  const Isometry3d back = kr210.fk(r.joints);
  CHECK((back.translation() - target.translation()).norm() < 2e-5);
  CHECK(rotation_angle(back, target) < 2e-5);
  // position-only: the orientation is free, the position is met
  options.position_only = true;
  const kinplan::IkResult p = kr210.ik(target, q + VectorXd::Constant(6, 0.2), options);
  CHECK(p.success);
  CHECK((kr210.fk(p.joints).translation() - target.translation()).norm() < 2e-5);
  // the method travels: FABRIK solves position targets (and refuses full poses)
  kinplan::IkOptions fabrik;
  fabrik.method = kinplan::IkMethod::Fabrik;
  fabrik.position_only = true;
  fabrik.position_tolerance = 1e-4;
  fabrik.max_iterations = 1000;
  const kinplan::IkResult f = kr210.ik(target, q + VectorXd::Constant(6, 0.05), fabrik);
  CHECK(f.success);
  CHECK((kr210.fk(f.joints).translation() - target.translation()).norm() < 2e-4);
  fabrik.position_only = false;
  try {
    kr210.ik(target, q, fabrik);
    CHECK(!"FABRIK with a full pose target was accepted");
  } catch (const kinplan::Error& e) {
    CHECK(e.code() == grpc::StatusCode::INVALID_ARGUMENT);
    CHECK(e.details().find("options.method") != std::string::npos);
  }
}

void jacobian_matches_finite_differences(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  const VectorXd q = vec({0.2, -1.6, 1.7, 0.3, 0.8, -0.2});
  const Eigen::MatrixXd J = kr210.jacobian(q);
  CHECK(J.rows() == 6 && J.cols() == 6);
  const double h = 1e-6;
  for (int i = 0; i < 6; ++i) {
    VectorXd up = q, down = q;
    up[i] += h;
    down[i] -= h;
    const Isometry3d a = kr210.fk(up), b = kr210.fk(down);
    const Vector3d v = (a.translation() - b.translation()) / (2 * h);
    const Eigen::AngleAxisd turn(a.linear() * b.linear().transpose());
    const Vector3d w = turn.axis() * turn.angle() / (2 * h);
    CHECK((J.col(i).head<3>() - v).norm() < 1e-6);
    CHECK((J.col(i).tail<3>() - w).norm() < 1e-6);
  }
}

void stream_ik_session(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  const VectorXd q0 = vec({0.2, -1.6, 1.7, 0.3, 0.8, -0.2});
  const Isometry3d start = kr210.fk(q0);
  kinplan::IkStream s = kr210.stream_ik({}, q0);
  VectorXd previous = q0;
  for (int k = 1; k <= 5; ++k) {
    Isometry3d target = start;
    target.translation() += Vector3d(0.0, 0.002 * k, 0.0);  // 2 mm steps
    const kinplan::IkResult r = s.solve(target);
    CHECK(r.sequence == static_cast<uint64_t>(k));
    CHECK(r.success);
    CHECK((kr210.fk(r.joints).translation() - target.translation()).norm() < 2e-5);
    // warm-started: a 2 mm step moves the joints a little, not to another branch
    CHECK((r.joints - previous).cwiseAbs().maxCoeff() < 0.05);
    previous = r.joints;
  }
  // pipelined: two targets out, two answers back in order
  const uint64_t a = s.send(start), b = s.send(kr210.fk(q0 + VectorXd::Constant(6, 0.01)));
  CHECK(s.read().sequence == a);
  CHECK(s.read().sequence == b);
  s.close();
}

void plan_around_a_box(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  // A1 turns from -0.8 to 0.8 rad: the tool sweeps an arc of radius 1.64 m at
  // 1.5 m height, through (1.64, 0, 1.5) halfway
  const VectorXd start = vec({-0.8, -1.6, 1.7, 0.0, 0.8, 0.0});
  const VectorXd goal = vec({0.8, -1.6, 1.7, 0.0, 0.8, 0.0});
  const Vector3d halfway = kr210.fk((start + goal) / 2).translation();
  CHECK((halfway - Vector3d(1.64, 0.0, 1.4955)).norm() < 0.01);
  // a block on that arc: the straight joint-space motion runs the tool into it
  kinplan::Scene scene = {kinplan::Obstacle::box("block", Isometry3d(Eigen::Translation3d(halfway)),
                                                 Vector3d(0.3, 0.3, 0.3))};
  kinplan::PlanOptions options;
  options.seed = 3;
  const kinplan::PlanResult r = kr210.plan(start, goal, scene, options);
  if (r.status != kinplan::PlanStatus::Succeeded) std::fprintf(stderr, "  plan: %s\n", r.message.c_str());
  CHECK(r.status == kinplan::PlanStatus::Succeeded);
  CHECK(r.valid);
  CHECK(r.positions.size() > 2);  // not the straight line
  if (r.positions.size() < 2) return;
  CHECK((r.positions.front() - start).norm() < 1e-9);
  CHECK((r.positions.back() - goal).norm() < 1e-9);
  CHECK(r.times.front() == 0.0);
  CHECK_NEAR(r.times.back(), r.duration, 1e-9);
  // no waypoint puts the tool inside the block (its half-size plus nothing)
  for (const VectorXd& q : r.positions) {
    const Vector3d d = (kr210.fk(q).translation() - halfway).cwiseAbs();
    CHECK(d.maxCoeff() > 0.15);
  }
  // a goal with the tool inside a box is refused as a status, not an error
  kinplan::Scene around_goal = {kinplan::Obstacle::box(
      "crate", Isometry3d(Eigen::Translation3d(kr210.fk(goal).translation())),
      Vector3d(0.3, 0.3, 0.3))};
  const kinplan::PlanResult bad = kr210.plan(start, goal, around_goal, options);
  CHECK(bad.status == kinplan::PlanStatus::InvalidGoal);
  CHECK(!bad.colliding.empty());
}

void urdf_robot_resent_after_eviction(kinplan::Client& c, const std::string& repo) {
  const std::string dir = repo + "/crates/kinplan-core/src/robot/builtin/";
  kinplan::Robot ur5 = c.robot_from_urdf(read_file(dir + "ur5.urdf"));
  kinplan::Robot kr120 = c.robot_from_urdf(read_file(dir + "kuka_kr120_r2500_pro.urdf"));
  const VectorXd q = vec({0.1, -0.5, 0.4, 0.2, 0.3, 0.6});
  const Isometry3d expected = c.robot("ur5").fk(q);
  CHECK(ur5.model_id().empty());
  CHECK((ur5.fk(q).translation() - expected.translation()).norm() < 1e-12);
  CHECK(ur5.model_id().size() == 32);  // SHA-256 of the text
  // with --model-cache 1 this evicts the UR5; the next UR5 call names a model
  // the server no longer holds, gets NOT_FOUND, and is sent again as text
  CHECK(kr120.fk(q).translation().norm() > 0.5);
  CHECK((ur5.fk(q).translation() - expected.translation()).norm() < 1e-12);
  CHECK(ur5.jacobian(q).cols() == 6);
  CHECK(kr120.describe().dof() == 6);
  // and through a stream
  kinplan::IkStream s = ur5.stream_ik({}, q);
  CHECK(s.solve(expected).success);
  s.close();
  bool refused = false;
  try {
    c.robot_from_urdf("robots/ur5.urdf");
  } catch (const kinplan::Error& e) {
    refused = e.code() == grpc::StatusCode::INVALID_ARGUMENT;
  }
  CHECK(refused);
}

/// Runs `f`, expecting a kinplan::Error with `code` whose message contains `needle`.
void expect_error(const char* what, grpc::StatusCode code, const std::string& needle,
                  const std::function<void()>& f) {
  try {
    f();
    std::fprintf(stderr, "  FAILED %s: no error\n", what);
    ++failures;
  } catch (const kinplan::Error& e) {
    if (e.code() != code || e.details().find(needle) == std::string::npos) {
      std::fprintf(stderr, "  FAILED %s: got %s, wanted %s containing '%s'\n", what, e.what(),
                   kinplan::Error::code_name(code), needle.c_str());
      ++failures;
    }
  }
}

void bad_input_is_the_documented_error(kinplan::Client& c) {
  kinplan::Robot kr210 = c.robot(kKr210);
  Isometry3d nan_pose = kr210.fk(VectorXd::Zero(6));
  nan_pose.translation().x() = std::nan("");
  expect_error("NaN target", grpc::StatusCode::INVALID_ARGUMENT, "target.position.x: must be finite",
               [&] { kr210.ik(nan_pose); });
  expect_error("NaN joint", grpc::StatusCode::INVALID_ARGUMENT, "joint_positions",
               [&] { kr210.fk(vec({0, 0, std::nan(""), 0, 0, 0})); });
  expect_error("wrong dof", grpc::StatusCode::INVALID_ARGUMENT, "joint_positions",
               [&] { kr210.fk(vec({0, 0, 0})); });
  expect_error("unknown robot", grpc::StatusCode::NOT_FOUND, "no_such_robot",
               [&] { c.robot("no_such_robot").fk(VectorXd::Zero(6)); });
  // a NaN target in the middle of a stream ends it, naming the field
  expect_error("NaN stream target", grpc::StatusCode::INVALID_ARGUMENT, "target", [&] {
    kinplan::IkStream s = kr210.stream_ik();
    s.solve(kr210.fk(VectorXd::Zero(6)));
    s.solve(nan_pose);
  });
  // A 1 ms deadline on a long call. IK and planning have time budgets: they
  // answer inside the deadline with a TIME_BUDGET / TIMEOUT status by design.
  // FK of 200,000 states (9.6 MB of joints) has none: it cannot be sent,
  // computed and answered in 1 ms.
  const Eigen::MatrixXd many = Eigen::MatrixXd::Constant(200000, 6, 0.1);
  expect_error("1 ms deadline", grpc::StatusCode::DEADLINE_EXCEEDED, "",
               [&] { kr210.fk_batch(many, std::chrono::milliseconds(1)); });
  // IK under a 1 ms deadline is a status, not an error
  kinplan::IkOptions hard;
  hard.num_solutions = 1000;
  hard.max_restarts = 100000;
  try {
    const kinplan::IkResult r = kr210.ik(kr210.fk(VectorXd::Zero(6)), VectorXd(), hard,
                                         std::chrono::milliseconds(1));
    CHECK(r.status == kinplan::IkStatus::TimeBudget);
  } catch (const kinplan::Error& e) {
    // ... unless the reply itself missed the deadline on a loaded machine
    CHECK(e.code() == grpc::StatusCode::DEADLINE_EXCEEDED);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: client_tests <address> [repository root]\n");
    return 2;
  }
  const std::string repo = argc > 2 ? argv[2] : KINPLAN_REPO_ROOT;
  kinplan::ClientOptions options;
  options.timeout = std::chrono::seconds(60);
  kinplan::Client client(argv[1], options);
  client.wait_for_ready(std::chrono::seconds(30));
  const std::pair<const char*, std::function<void()>> tests[] = {
      {"fk_matches_published_kinematics", [&] { fk_matches_published_kinematics(client); }},
      {"ik_round_trip", [&] { ik_round_trip(client); }},
      {"jacobian_matches_finite_differences", [&] { jacobian_matches_finite_differences(client); }},
      {"stream_ik_session", [&] { stream_ik_session(client); }},
      {"plan_around_a_box", [&] { plan_around_a_box(client); }},
      {"urdf_robot_resent_after_eviction", [&] { urdf_robot_resent_after_eviction(client, repo); }},
      {"bad_input_is_the_documented_error", [&] { bad_input_is_the_documented_error(client); }},
  };
  for (const auto& [name, run] : tests) {
    const int before = failures;
    try {
      run();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "  FAILED: unexpected exception: %s\n", e.what());
      ++failures;
    }
    std::printf("%s %s\n", failures == before ? "ok  " : "FAIL", name);
  }
  std::printf("%s: %d failed check(s)\n", failures == 0 ? "PASSED" : "FAILED", failures);
  return failures == 0 ? 0 : 1;
}
