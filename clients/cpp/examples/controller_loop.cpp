// A robot controller's fixed-cycle loop over StreamIk: every cycle (12 ms, the
// KUKA interpolation cycle) it sends the next set-point of a Cartesian path and
// waits for the joint answer, as an RSI/EGM bridge or a ros2_control hardware
// interface would.
//
//     controller_loop [--address 127.0.0.1:50051] [--cycles 10000] [--period-ms 12]
//                     [--csv cycles.csv]
//
// Path: the S2 10 mm circle on the KUKA KR 210 R2700 extra, as in
// examples/ik_latency.rs and clients/python/examples/ik_latency.py: start at
// FK(q0), q0 = (0.2, -1.6, 1.7, 0.3, 0.8, -0.2), centre 10 mm along -x from
// there, target k at angle 2 pi k / 1000 in the x-y plane, orientation fixed.
// Each target is solved from the previous answer (StreamIk's warm start).
//
// Timing: cycle k starts at t0 + k * period on the steady clock
// (sleep_until an absolute deadline, so that errors do not accumulate).
// Measured per cycle: latency = request written -> answer read; a cycle is
// missed when its answer is not back by the start of the next cycle; jitter =
// how late the cycle actually woke after its scheduled start.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "kinplan/client.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

struct Args {
  std::string address = "127.0.0.1:50051";
  int cycles = 10000;
  double period_ms = 12.0;
  std::string csv;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const bool has_value = i + 1 < argc;
    if (flag == "--address" && has_value) {
      a.address = argv[++i];
    } else if (flag == "--cycles" && has_value) {
      a.cycles = std::atoi(argv[++i]);
    } else if (flag == "--period-ms" && has_value) {
      a.period_ms = std::atof(argv[++i]);
    } else if (flag == "--csv" && has_value) {
      a.csv = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: controller_loop [--address host:port] [--cycles n] [--period-ms ms] "
                   "[--csv file]\n");
      std::exit(2);
    }
  }
  if (a.cycles < 1 || !(a.period_ms > 0)) {
    std::fprintf(stderr, "--cycles must be >= 1 and --period-ms > 0\n");
    std::exit(2);
  }
  return a;
}

/// Nearest-rank percentile of sorted values (as the Rust and Python examples).
double pct(const std::vector<double>& sorted, double p) {
  return sorted[static_cast<size_t>(std::llround((sorted.size() - 1) * p))];
}

void summary(const char* label, std::vector<double> us) {
  std::sort(us.begin(), us.end());
  std::printf("%-26s p50 %7.1f  p90 %7.1f  p99 %7.1f  p99.9 %7.1f  max %8.1f µs\n", label,
              pct(us, 0.5), pct(us, 0.9), pct(us, 0.99), pct(us, 0.999), us.back());
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse(argc, argv);
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double, std::milli>(args.period_ms));
  try {
    kinplan::Client client(args.address);
    client.wait_for_ready(std::chrono::seconds(10));
    kinplan::Robot kr210 = client.robot("kuka_kr210_r2700_extra");

    Eigen::VectorXd q0(6);
    q0 << 0.2, -1.6, 1.7, 0.3, 0.8, -0.2;
    const Eigen::Isometry3d start = kr210.fk(q0);
    const Eigen::Vector3d centre = start.translation() - Eigen::Vector3d(0.01, 0.0, 0.0);
    auto target = [&](int k) {
      const double a = 2 * kPi * k / 1000.0;
      Eigen::Isometry3d T = start;
      T.translation() = centre + 0.01 * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
      return T;
    };

    // The session lasts the whole run: its deadline is the run's length plus a margin.
    const kinplan::Duration session =
        kinplan::Duration(args.period_ms * 1e-3 * (args.cycles + 100) + 30.0);
    kinplan::IkStream stream = kr210.stream_ik({}, q0, session);
    // warm-up outside the measurement: connection, model, first allocations
    for (int k = 0; k < 20; ++k) stream.solve(target(0));

    std::vector<double> latency(args.cycles), jitter(args.cycles), server(args.cycles);
    std::vector<double> position_error(args.cycles);
    std::vector<char> converged(args.cycles);
    int missed = 0;
    const Clock::time_point t0 = Clock::now() + std::chrono::milliseconds(50);
    for (int k = 0; k < args.cycles; ++k) {
      const Clock::time_point scheduled = t0 + k * period;
      std::this_thread::sleep_until(scheduled);
      const Eigen::Isometry3d T = target(k);  // the set-point of this cycle
      const Clock::time_point sent = Clock::now();
      const kinplan::IkResult r = stream.solve(T);
      const Clock::time_point answered = Clock::now();
      latency[k] = std::chrono::duration<double, std::micro>(answered - sent).count();
      jitter[k] = std::chrono::duration<double, std::micro>(sent - scheduled).count();
      server[k] = static_cast<double>(r.server_elapsed_us);
      position_error[k] = r.position_error;
      converged[k] = r.success;
      if (answered > scheduled + period) ++missed;
    }
    stream.close();

    const int n = args.cycles;
    const long within_1ms = std::count_if(latency.begin(), latency.end(),
                                          [](double us) { return us <= 1000.0; });
    const long not_converged = std::count(converged.begin(), converged.end(), 0);
    std::printf("C++ controller loop: %d cycles of %.3f ms, StreamIk on %s, KR 210 10 mm circle\n",
                n, args.period_ms, args.address.c_str());
    summary("latency (sent->answer)", latency);
    summary("server solve (elapsed_us)", server);
    summary("cycle-start jitter", jitter);
    std::printf("answered within 1 ms: %ld / %d = %.3f %%\n", within_1ms, n, 100.0 * within_1ms / n);
    std::printf("missed cycles (answer after the next cycle's start): %d\n", missed);
    std::printf("not converged: %ld; max position error %.3g m\n", not_converged,
                *std::max_element(position_error.begin(), position_error.end()));

    if (!args.csv.empty()) {
      std::ofstream csv(args.csv);
      csv << "cycle,jitter_us,latency_us,server_us,converged,position_error_m\n";
      for (int k = 0; k < n; ++k) {
        csv << k << ',' << jitter[k] << ',' << latency[k] << ',' << server[k] << ','
            << int(converged[k]) << ',' << position_error[k] << '\n';
      }
      std::printf("per-cycle figures written to %s\n", args.csv.c_str());
    }
  } catch (const kinplan::Error& e) {
    std::fprintf(stderr, "kinplan error: %s\n", e.what());
    return 1;
  }
  return 0;
}
