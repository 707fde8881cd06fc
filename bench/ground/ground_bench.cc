// Ground stage benchmark: wall-clock milliseconds per scan of segmentation +
// per-scan plane fit (ScanProcessor::Process; one row adds deskewing), single
// thread, on
//   - simulated VLP-16 street scans (ray-cast, ~25k points),
//   - the real KITTI HDL-64E scan kitti_000000.bin (124,668 points),
//   - a VLP-16-like subsample of it (KITTI beams within 0.25 deg of the VLP-16
//     elevations, every 2nd point; the proxy of the reference note, ~12k).
// Anchors: the Patchwork++ reference implementation (segmentation only,
// no plane fit) measured on this machine class: 20.7 ms on kitti_000000 and
// 3.75 ms on the VLP-16-like subsample (shared/reference/patchwork.md §3.3).
// The anchor cannot be re-run here (no copy of that code), so besides wall
// time the thread CPU time is reported: on a shared 2-core machine under load
// it is the figure that stays comparable with an unloaded wall-time anchor.
//
//   ground_bench [--fixtures=DIR] [--passes=N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/geometry/angles.h"
#include "common/imu/gyro_integrator.h"
#include "common/imu/imu_reading.h"
#include "common/io/params.h"
#include "stages/ground/default_params_text.h"
#include "stages/ground/scan_processor.h"
#include "tests/testing/synthetic_lidar.h"

namespace {

using Clock = std::chrono::steady_clock;
using tiltcal::proto::Scan;

// CPU time of the calling thread, ms: insensitive to other processes on a
// shared machine (wall time is also reported).
double ThreadCpuMs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct Timing {
  double median_ms = 0, p95_ms = 0;
  double cpu_median_ms = 0;
  double segment_ms = 0, fit_ms = 0;  // medians of the two steps (wall)
  uint32_t points = 0, ground = 0;
  bool valid = false;
};

Timing TimeScans(const tiltcal::proto::GroundParams& params, const std::vector<Scan>& scans,
                 int passes, tiltcal::ground::Deskewer* deskewer = nullptr) {
  tiltcal::ground::ScanProcessor processor(params, tiltcal::ground::GroundFrame(), deskewer);
  std::vector<double> ms, cpu, seg, fit;
  Timing t;
  for (int pass = 0; pass < passes; ++pass) {
    for (const Scan& original : scans) {
      Scan scan = original;  // copy outside the timed region
      const double c0 = ThreadCpuMs();
      const auto a = Clock::now();
      const tiltcal::proto::GroundPlane plane = processor.Process(&scan);
      const auto b = Clock::now();
      cpu.push_back(ThreadCpuMs() - c0);
      ms.push_back(std::chrono::duration<double, std::milli>(b - a).count());
      seg.push_back(processor.last_segment_s() * 1e3);
      fit.push_back(processor.last_fit_s() * 1e3);
      t.points = plane.num_points();
      t.ground = plane.num_ground_points();
      t.valid = plane.valid();
    }
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  t.cpu_median_ms = median(cpu);
  t.segment_ms = median(seg);
  t.fit_ms = median(fit);
  std::sort(ms.begin(), ms.end());
  t.median_ms = ms[ms.size() / 2];
  t.p95_ms = ms[std::min(ms.size() - 1, static_cast<size_t>(0.95 * ms.size()))];
  return t;
}

bool ReadKitti(const std::string& path, Scan* scan) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t n = bytes.size() / 16;
  std::vector<float> v(n * 4);
  std::memcpy(v.data(), bytes.data(), n * 16);
  for (size_t i = 0; i < n; ++i) {
    scan->add_x(v[4 * i]);
    scan->add_y(v[4 * i + 1]);
    scan->add_z(v[4 * i + 2]);
    scan->add_intensity(v[4 * i + 3]);
  }
  return n > 0;
}

Scan VlpLikeSubsample(const Scan& kitti) {
  Scan out;
  int kept = 0;
  for (int i = 0; i < kitti.x_size(); ++i) {
    const double r = std::hypot(kitti.x(i), kitti.y(i));
    const double el = tiltcal::geometry::RadToDeg(std::atan2(kitti.z(i), r));
    const double nearest = std::round((el + 15.0) / 2.0) * 2.0 - 15.0;
    if (nearest < -15.0 || nearest > 15.0 || std::fabs(el - nearest) > 0.25) continue;
    if (kept++ % 2 != 0) continue;
    out.add_x(kitti.x(i));
    out.add_y(kitti.y(i));
    out.add_z(kitti.z(i));
    out.add_intensity(kitti.intensity(i));
  }
  return out;
}

void PrintRow(const char* name, const Timing& t, double anchor_ms) {
  std::printf("%-36s %7u %7u %5s %8.3f %8.3f %8.3f %8.3f %8.3f", name, t.points, t.ground,
              t.valid ? "yes" : "no", t.cpu_median_ms, t.median_ms, t.p95_ms, t.segment_ms,
              t.fit_ms);
  if (anchor_ms > 0) {
    std::printf(" %7.2f %6.2fx %6.2fx\n", anchor_ms, anchor_ms / t.cpu_median_ms,
                anchor_ms / t.median_ms);
  } else {
    std::printf(" %7s %7s %7s\n", "-", "-", "-");
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string fixtures = std::string(TILTCAL_SOURCE_DIR) + "/../shared/fixtures";
  int passes = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--fixtures=", 0) == 0) fixtures = arg.substr(11);
    if (arg.rfind("--passes=", 0) == 0) passes = std::max(1, std::atoi(arg.c_str() + 9));
  }
  // The shipped defaults (stages/ground/default_params.txtpb, compiled in).
  tiltcal::proto::GroundParams params;
  const tiltcal::Status status = tiltcal::LoadParamsOrDefaults(
      "", tiltcal::ground::DefaultParamsText(), &params);
  if (!status.ok()) {
    std::fprintf(stderr, "ground_bench: %s\n", status.message().c_str());
    return 1;
  }

  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) {
    std::printf("load average (1 min): %.2f — wall times are inflated on a busy machine; the\n"
                "thread CPU time is the figure to compare with the anchors.\n\n", load[0]);
  }
  std::printf("%-36s %7s %7s %5s %8s %8s %8s %8s %8s %7s %7s %7s\n", "input", "points", "ground",
              "valid", "cpu", "wall", "wall p95", "segment", "fit", "anchor", "x(cpu)",
              "x(wall)");
  std::printf("%-36s %7s %7s %5s %8s %8s %8s %8s %8s %7s\n", "", "", "", "", "ms", "ms", "ms",
              "ms", "ms", "ms");

  // Simulated VLP-16 scans (10 street scenes, sensor 0.85 m high).
  std::vector<Scan> vlp;
  for (int k = 0; k < 10; ++k) {
    tiltcal::testing::SyntheticPose pose;
    pose.position_g = Eigen::Vector3d(0, 0, 0.85);
    pose.g_from_lidar = tiltcal::testing::RollPitchYaw(0.003 * k, -0.002 * k, 0.3 * k);
    vlp.push_back(tiltcal::testing::CastScan(tiltcal::testing::StreetScene(k),
                                             tiltcal::testing::SyntheticLidar::Vlp16(), pose,
                                             k, k));
  }
  PrintRow("simulated VLP-16 (street, 0.85 m)", TimeScans(params, vlp, passes), 0.0);
  {
    // The same scans with deskewing (IMU at 200 Hz turning at 0.5 rad/s).
    std::vector<tiltcal::imu::ImuReading> imu;
    for (int i = 0; i <= 600; ++i) {  // from -1 s to 2 s
      tiltcal::imu::ImuReading reading;
      reading.time_s = 0.005 * i;
      reading.angular_velocity_radps = Eigen::Vector3d(0.0, 0.0, 0.5);
      imu.push_back(reading);
    }
    tiltcal::imu::GyroIntegrator integrator(imu, Eigen::Vector3d::Zero());
    tiltcal::ground::Deskewer deskewer(&integrator, -1000000000LL, Eigen::Matrix3d::Identity(),
                                       params.deskew());
    PrintRow("  + deskewing (timing only)", TimeScans(params, vlp, passes, &deskewer), 0.0);
  }

  Scan kitti;
  if (!ReadKitti(fixtures + "/scans/kitti_000000.bin", &kitti)) {
    std::printf("KITTI fixture not found under %s/scans; skipped\n", fixtures.c_str());
    return 0;
  }
  PrintRow("KITTI 000000 VLP-16-like subsample", TimeScans(params, {VlpLikeSubsample(kitti)}, passes),
           3.75);
  PrintRow("KITTI 000000 (HDL-64E)", TimeScans(params, {kitti}, passes), 20.7);
  std::printf("\ncpu = median thread CPU time per scan (segmentation + plane fit + masks);\n"
              "anchor = Patchwork++ reference implementation, segmentation only, median wall\n"
              "time on the same input on this 2-core machine class (not re-measured here);\n"
              "x = anchor / ours.\n");
  return 0;
}
