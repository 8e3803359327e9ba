// OctoMap anchor for one depth frame: reads the frame's points written by
// `cargo run --release -p kinplan-core --example depth_frame -- write`
// (little-endian f32: origin xyz, then x y z per point), inserts them with
// OcTree::insertPointCloud at the given resolution `runs` times into fresh
// trees, prints the median and minimum time, and writes the last tree as .ot
// for the cell-by-cell comparison (`depth_frame -- compare`). Run by hand.
//
//   g++ -O2 -o target/insert_frame benches/octomap/insert_frame.cpp -loctomap -loctomath
//   target/insert_frame target/frame_points.bin 0.05 7 target/frame_octomap.ot
#include <octomap/octomap.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: insert_frame POINTS.bin RESOLUTION RUNS OUT.ot\n";
    return 2;
  }
  std::ifstream again(argv[1], std::ios::binary);
  std::vector<float> xyz;
  float f;
  while (again.read(reinterpret_cast<char*>(&f), sizeof f)) xyz.push_back(f);
  if (xyz.size() < 3 || xyz.size() % 3 != 0) {
    std::cerr << "bad points file\n";
    return 1;
  }
  octomap::point3d origin(xyz[0], xyz[1], xyz[2]);
  octomap::Pointcloud cloud;
  for (size_t i = 3; i < xyz.size(); i += 3) cloud.push_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  const double res = std::atof(argv[2]);
  const int runs = std::max(1, std::atoi(argv[3]));
  std::vector<double> ms, cpu;
  octomap::OcTree* last = nullptr;
  for (int r = 0; r < runs; ++r) {
    delete last;
    last = new octomap::OcTree(res);
    auto t0 = std::chrono::steady_clock::now();
    std::clock_t c0 = std::clock();
    last->insertPointCloud(cloud, origin);
    std::clock_t c1 = std::clock();
    auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    cpu.push_back(1000.0 * double(c1 - c0) / CLOCKS_PER_SEC);
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  std::sort(cpu.begin(), cpu.end());
  std::printf("octomap insertPointCloud: %zu points, res %.3f, median %.1f ms, min %.1f ms over %d runs\n",
              cloud.size(), res, sorted[sorted.size() / 2], sorted[0], runs);
  std::printf("  CPU time: median %.1f ms, min %.1f ms\n", cpu[cpu.size() / 2], cpu[0]);
  last->write(std::string(argv[4]));
  delete last;
  return 0;
}
