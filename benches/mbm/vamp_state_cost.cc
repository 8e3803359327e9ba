// VAMP's cost per state check on a MotionBenchMaker scene, without its
// Python binding: the scene's primitives as vamp_state_cost.py wrote them
// (built as vamp.problem_dict_to_vamp builds them), the uniform random
// states it wrote, and VAMP's Panda `fkcc` (forward kinematics and sphere
// tests of a block of eight states in SIMD lanes, float32) on blocks of
// eight, timed with steady_clock over `passes` passes (the minimum pass).
// Prints one line: states, VAMP-free states, ns per state over all states
// in blocks of eight (a block stops at its first collision, as VAMP's
// motion checks do), and ns per state over blocks of free states only (the
// whole check). Writes the per-state verdicts (one byte each, 1 = free) to
// <states>.vamp for mbm_bench --states-from to compare with ours.
//
//   g++ -std=c++17 -O3 -march=native -mavx2 -fno-math-errno -fno-signed-zeros
//       -fno-trapping-math -fno-rounding-math -ffp-contract=fast -fassociative-math
//       -I/work/vampwork/src/src/impl -I/work/vampwork/deps/pdqsort -I/usr/include/eigen3
//       benches/mbm/vamp_state_cost.cc -o target/vamp_state_cost
//   target/vamp_state_cost <env.txt> <states.bin> <passes>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <vamp/collision/factory.hh>
#include <vamp/robots/panda.hh>

using Robot = vamp::robots::Panda;
static constexpr std::size_t rake = vamp::FloatVectorWidth;
using EnvIn = vamp::collision::Environment<float>;
using EnvVec = vamp::collision::Environment<vamp::FloatVector<rake>>;
namespace vf = vamp::collision::factory;

static EnvIn read_env(const char *path)
{
    EnvIn env;
    std::ifstream in(path);
    std::string kind;
    while (in >> kind)
    {
        if (kind == "sphere")
        {
            float x, y, z, r;
            in >> x >> y >> z >> r;
            env.spheres.emplace_back(vf::sphere::flat(x, y, z, r));
        }
        else if (kind == "cuboid")
        {
            float x, y, z, a, b, c, hx, hy, hz;
            in >> x >> y >> z >> a >> b >> c >> hx >> hy >> hz;
            auto s = vf::cuboid::flat(x, y, z, a, b, c, hx, hy, hz);
            (s.axis_3_z == 1. ? env.z_aligned_cuboids : env.cuboids).emplace_back(s);
        }
        else if (kind == "capsule")
        {
            float x, y, z, a, b, c, r, l;
            in >> x >> y >> z >> a >> b >> c >> r >> l;
            auto s = vf::cylinder::center::flat(x, y, z, a, b, c, r, l);
            (s.xv == 0. and s.yv == 0. ? env.z_aligned_capsules : env.capsules).emplace_back(s);
        }
        else
        {
            std::fprintf(stderr, "%s: unknown primitive %s\n", path, kind.c_str());
            std::exit(2);
        }
    }
    env.sort();
    return env;
}

static Robot::ConfigurationBlock<rake> block_of(const std::vector<double> &q, const std::vector<std::size_t> &rows)
{
    Robot::ConfigurationBlock<rake> block;
    for (std::size_t j = 0; j < Robot::dimension; ++j)
    {
        alignas(32) std::array<float, rake> lane{};
        for (std::size_t l = 0; l < rake; ++l)
        {
            lane[l] = static_cast<float>(q[rows[std::min(l, rows.size() - 1)] * Robot::dimension + j]);
        }
        block[j] = vamp::FloatVector<rake>(lane);
    }
    return block;
}

int main(int argc, char **argv)
{
    if (argc != 4)
    {
        std::fprintf(stderr, "usage: vamp_state_cost <env.txt> <states.bin> <passes>\n");
        return 2;
    }
    const EnvVec env(read_env(argv[1]));
    std::ifstream in(argv[2], std::ios::binary | std::ios::ate);
    std::vector<double> states(static_cast<std::size_t>(in.tellg()) / sizeof(double));
    in.seekg(0);
    in.read(reinterpret_cast<char *>(states.data()), states.size() * sizeof(double));
    const std::size_t n = states.size() / Robot::dimension;
    const int passes = std::atoi(argv[3]);

    // verdicts state by state (a block of eight copies)
    std::vector<char> free(n);
    std::vector<std::size_t> free_rows;
    for (std::size_t i = 0; i < n; ++i)
    {
        auto block = block_of(states, {i});
        free[i] = Robot::fkcc<rake>(env, block) ? 1 : 0;
        if (free[i])
        {
            free_rows.push_back(i);
        }
    }
    std::ofstream(std::string(argv[2]) + ".vamp", std::ios::binary).write(free.data(), n);

    auto blocks_of = [&](const std::vector<std::size_t> &rows)
    {
        std::vector<Robot::ConfigurationBlock<rake>> out;
        for (std::size_t i = 0; i + rake <= rows.size(); i += rake)
        {
            out.push_back(block_of(states, std::vector<std::size_t>(rows.begin() + i, rows.begin() + i + rake)));
        }
        return out;
    };
    std::vector<std::size_t> all(n);
    for (std::size_t i = 0; i < n; ++i)
    {
        all[i] = i;
    }
    auto time_blocks = [&](std::vector<Robot::ConfigurationBlock<rake>> &blocks)
    {
        double best = 1e30;
        volatile int sink = 0;
        for (int p = 0; p < passes; ++p)
        {
            auto t = std::chrono::steady_clock::now();
            int valid = 0;
            for (auto &b : blocks)
            {
                valid += Robot::fkcc<rake>(env, b);
            }
            auto ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t).count();
            sink = sink + valid;
            best = std::min(best, ns / (blocks.size() * rake));
        }
        return best;
    };
    auto all_blocks = blocks_of(all);
    auto free_blocks = blocks_of(free_rows);
    const double all_ns = time_blocks(all_blocks);
    const double free_ns = free_blocks.empty() ? 0.0 : time_blocks(free_blocks);
    std::printf("%zu %zu %.2f %.2f\n", n, free_rows.size(), all_ns, free_ns);
    return 0;
}
