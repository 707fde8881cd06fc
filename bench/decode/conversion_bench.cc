// PointCloud2 -> Scan conversion benchmark: thread CPU nanoseconds per point
// of ConvertPointCloud2ToScan on VLP-16-sized clouds (16 rings x 1,800
// firings, the ros-drivers/velodyne layout: x y z intensity FLOAT32, ring
// UINT16, time FLOAT32, point_step 22), with a share of no-return points
// (NaN, or at zero range) scattered as a real sensor reports them.
// Rows, each against anchors measured in the same run:
//   fast      the specialised loop the decoder takes for this layout
//   generic   the loop driven by the PointField list (allow_fast_path false)
//   memcpy    copying the cloud's bytes once (the memory floor)
//
//   conversion_bench [--clouds=N] [--passes=N] [--no_return=F]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/geometry/angles.h"
#include "stages/decode/point_cloud_conversion.h"

namespace {

using tiltcal::ros1::PointCloud2View;
using tiltcal::ros1::PointField;

constexpr int kRings = 16;
constexpr int kFirings = 1800;
constexpr uint32_t kPointStep = 22;

double ThreadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// One cloud's bytes: rays over 360 deg, ranges 2-60 m, times -0.1-0 s, and a
// fraction `no_return` of points NaN (two thirds) or at the origin.
std::vector<uint8_t> MakeCloudBytes(std::mt19937* rng, double no_return) {
  std::uniform_real_distribution<float> range(2.0f, 60.0f);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<uint8_t> bytes(size_t{kRings} * kFirings * kPointStep);
  uint8_t* p = bytes.data();
  for (int f = 0; f < kFirings; ++f) {
    for (int r = 0; r < kRings; ++r, p += kPointStep) {
      const float azimuth = 2.0f * static_cast<float>(M_PI) * f / kFirings;
      const float elevation = static_cast<float>(tiltcal::geometry::DegToRad(-15.0 + 2.0 * r));
      float d = range(*rng);
      const double u = unit(*rng);
      if (u < no_return) {
        d = u < 2.0 * no_return / 3.0 ? std::numeric_limits<float>::quiet_NaN() : 0.0f;
      }
      const float xyz[3] = {d * std::cos(elevation) * std::cos(azimuth),
                            d * std::cos(elevation) * std::sin(azimuth), d * std::sin(elevation)};
      const float intensity = static_cast<float>(static_cast<int>(unit(*rng) * 255));
      const uint16_t ring = static_cast<uint16_t>(r);
      const float time = -0.1f + 0.1f * f / kFirings + 2.304e-6f * r;  // stamp = last firing
      std::memcpy(p, xyz, 12);
      std::memcpy(p + 12, &intensity, 4);
      std::memcpy(p + 16, &ring, 2);
      std::memcpy(p + 18, &time, 4);
    }
  }
  return bytes;
}

PointCloud2View ViewOf(const std::vector<uint8_t>& bytes) {
  PointCloud2View cloud;
  cloud.header.stamp = {1700000000, 0};
  cloud.header.frame_id = "velodyne";
  cloud.height = 1;
  cloud.width = kRings * kFirings;
  cloud.point_step = kPointStep;
  cloud.row_step = kPointStep * cloud.width;
  cloud.fields = {
      {"x", 0, tiltcal::ros1::kFloat32, 1},    {"y", 4, tiltcal::ros1::kFloat32, 1},
      {"z", 8, tiltcal::ros1::kFloat32, 1},    {"intensity", 12, tiltcal::ros1::kFloat32, 1},
      {"ring", 16, tiltcal::ros1::kUint16, 1}, {"time", 18, tiltcal::ros1::kFloat32, 1}};
  cloud.data = bytes.data();
  cloud.data_size = static_cast<uint32_t>(bytes.size());
  return cloud;
}

}  // namespace

int main(int argc, char** argv) {
  int num_clouds = 50;
  int passes = 5;
  double no_return = 0.08;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--clouds=", 0) == 0) {
      num_clouds = std::atoi(arg.c_str() + 9);
    } else if (arg.rfind("--passes=", 0) == 0) {
      passes = std::atoi(arg.c_str() + 9);
    } else if (arg.rfind("--no_return=", 0) == 0) {
      no_return = std::atof(arg.c_str() + 12);
    } else {
      num_clouds = 0;  // the usage below
      break;
    }
  }
  if (num_clouds < 1 || passes < 1 || !(no_return >= 0.0 && no_return <= 1.0)) {
    std::fprintf(stderr,
                 "usage: conversion_bench [--clouds=N >= 1] [--passes=N >= 1] "
                 "[--no_return=F in [0, 1]]\n");
    return 2;
  }
  std::mt19937 rng(7);
  std::vector<std::vector<uint8_t>> clouds;
  for (int i = 0; i < num_clouds; ++i) clouds.push_back(MakeCloudBytes(&rng, no_return));
  const double points = double{kRings} * kFirings * num_clouds;

  tiltcal::proto::Scan scan;
  std::vector<uint8_t> copy(clouds[0].size());
  double best_fast = 1e30, best_generic = 1e30, best_memcpy = 1e30;
  size_t kept = 0;
  for (int pass = 0; pass < passes; ++pass) {
    for (const bool fast : {true, false}) {
      tiltcal::PointConversionOptions options;
      options.allow_fast_path = fast;
      kept = 0;
      const double start = ThreadCpuSeconds();
      for (const auto& bytes : clouds) {
        const tiltcal::Status status =
            tiltcal::ConvertPointCloud2ToScan(ViewOf(bytes), options, &scan);
        if (!status.ok()) {
          std::fprintf(stderr, "conversion failed: %s\n", status.message().c_str());
          return 1;
        }
        kept += scan.x_size();
      }
      const double ns = 1e9 * (ThreadCpuSeconds() - start) / points;
      double& best = fast ? best_fast : best_generic;
      if (ns < best) best = ns;
    }
    const double start = ThreadCpuSeconds();
    for (const auto& bytes : clouds) {
      std::memcpy(copy.data(), bytes.data(), bytes.size());
      asm volatile("" : : "r"(copy.data()) : "memory");
    }
    const double ns = 1e9 * (ThreadCpuSeconds() - start) / points;
    if (ns < best_memcpy) best_memcpy = ns;
  }
  std::printf(
      "PointCloud2 -> Scan, %d clouds of %d points (point_step %u), %.1f %% no-return, "
      "%zu points kept per pass; best of %d passes, thread CPU\n",
      num_clouds, kRings * kFirings, kPointStep, 100.0 * no_return, kept, passes);
  std::printf("%-10s %10s %12s %12s\n", "loop", "ns/point", "vs generic", "vs memcpy");
  auto row = [&](const char* name, double ns) {
    std::printf("%-10s %10.2f %11.2fx %11.2fx\n", name, ns, best_generic / ns, best_memcpy / ns);
  };
  row("fast", best_fast);
  row("generic", best_generic);
  row("memcpy", best_memcpy);
  return 0;
}
