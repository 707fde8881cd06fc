#include "stages/simulate/simulate.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "bag/ros1/bag_writer.h"
#include "bag/ros1/message_encoding.h"
#include "common/cli/command_line.h"
#include "common/io/atomic_file.h"
#include "common/io/provenance.h"
#include "common/io/text_proto.h"
#include "stages/simulate/imu_simulator.h"
#include "stages/simulate/point_cloud_layout.h"
#include "stages/simulate/simulation_truth.h"
#include "stages/simulate/tf_static_writer.h"

namespace tiltcal::simulate {

namespace {

ros1::ChunkCompression ToCompression(proto::SimBagParams::Compression c) {
  switch (c) {
    case proto::SimBagParams::BZ2: return ros1::ChunkCompression::kBz2;
    case proto::SimBagParams::LZ4: return ros1::ChunkCompression::kLz4;
    default: return ros1::ChunkCompression::kNone;
  }
}

using Clock = std::chrono::steady_clock;

// What a run did, for its summary line.
struct SimulateSummary {
  int num_imu_samples = 0;
  int num_scans = 0;
  uint64_t num_points = 0;
  uint64_t bag_bytes = 0;
  double raycast_seconds = 0.0;  // wall time in ray casting + serialization
  double total_seconds = 0.0;
};

// The bag being written and its two connections.
struct BagOutput {
  ros1::BagWriter* writer;
  uint32_t imu_connection;
  uint32_t lidar_connection;
};

// writing in order on this thread, each after the IMU samples up to its
// record time (IMU first on ties).
class ScanWriter {
 public:
  ScanWriter(const proto::SimulateParams& params, const Scenario& scenario, unsigned threads)
      : params_(params),
        scenario_(scenario),
        threads_(threads),
        batch_(static_cast<int>(threads) * 2),
        messages_(batch_),
        scans_(batch_),
        ok_(batch_) {}

  Status WriteAll(const BagOutput& bag, ImuSimulator* imu, const TruthFrames& frames,
                  proto::SimulationTruth* truth, std::ostream* progress,
                  SimulateSummary* summary) {
    const int num_scans = scenario_.num_scans;
    for (int first = 0; first < num_scans; first += batch_) {
      const int count = std::min(batch_, num_scans - first);
      const auto t0 = Clock::now();
      SimulateBatch(first, count);
      summary->raycast_seconds += std::chrono::duration<double>(Clock::now() - t0).count();
      for (int j = 0; j < count; ++j) {
        const int k = first + j;
        if (!scenario_.scan_kept[static_cast<size_t>(k)]) continue;
        const int64_t stamp = StampNs(scans_[j]);
        const int64_t record = scenario_.LidarRecordNs(scans_[j].stamp_true_ns);
        if (!ok_[j]) return Status::Error("scan " + std::to_string(k) + ": stamp is not a ROS time");
        TILTCAL_RETURN_IF_ERROR(imu->WriteUpTo(record, bag.imu_connection, bag.writer));
        TILTCAL_RETURN_IF_ERROR(bag.writer->Write(bag.lidar_connection, record, messages_[j]));
        summary->num_points += scans_[j].num_valid;
        FillTruthScan(scenario_, frames, scans_[j], scenario_.imu_start_stamp_ns, stamp,
                      truth->add_scans());
        if (progress != nullptr) {
          *progress << fmt::format("\rtiltcal_simulate: scan {} / {}{}", k + 1, num_scans,
                                   k + 1 == num_scans ? "\n" : "")
                    << std::flush;
        }
      }
    }
    return Status::Ok();
  }

 private:
  // The bag stamp of a sweep (LiDAR clock: IMU clock − τ, with the drift).
  int64_t StampNs(const SimulatedScan& scan) const {
    return scenario_.LidarStampNs(scan.stamp_true_ns);
  }

  // Simulates and serializes sweeps first .. first + count - 1.
  void SimulateBatch(int first, int count) {
    const auto& lp = params_.lidar();
    const bool ouster = scenario_.scan.model.kind == LidarModel::Kind::kOuster;
    const bool livox = scenario_.scan.model.kind == LidarModel::Kind::kLivox;
    auto work = [&](unsigned tid) {
      for (int j = static_cast<int>(tid); j < count; j += static_cast<int>(threads_)) {
        const int k = first + j;
        if (!scenario_.scan_kept[static_cast<size_t>(k)]) continue;  // left out, not simulated
        scans_[j] = SimulateSweep(scenario_.scan, *scenario_.trajectory, *scenario_.world,
                                  params_.seed(), k, &scenario_.pedestrians);
        ok_[j] = livox ? SerializeLivoxScan(scans_[j], static_cast<uint32_t>(k),
                                            StampNs(scans_[j]), lp.frame_id(), &messages_[j])
                       : SerializeScan(scans_[j], ouster, lp.append_surface_label(),
                                       static_cast<uint32_t>(k), StampNs(scans_[j]),
                                       lp.frame_id(), &messages_[j]);
        // Keep the counts; drop the points.
        scans_[j].points.clear();
        scans_[j].points.shrink_to_fit();
      }
    };
    std::vector<std::thread> pool;
    for (unsigned tid = 1; tid < threads_; ++tid) pool.emplace_back(work, tid);
    work(0);
    for (auto& th : pool) th.join();
  }

  const proto::SimulateParams& params_;
  const Scenario& scenario_;
  const unsigned threads_;
  const int batch_;
  std::vector<std::string> messages_;
  std::vector<SimulatedScan> scans_;
  std::vector<char> ok_;
};

void PrintSummary(std::ostream* log, const SimulateSummary& s) {
  if (log == nullptr) return;
  *log << fmt::format(
      "tiltcal_simulate: {} IMU samples, {} scans, {} points, {:.1f} MB bag; "
      "ray casting {:.2f} s, total {:.2f} s\n",
      s.num_imu_samples, s.num_scans, s.num_points, s.bag_bytes / 1e6, s.raycast_seconds,
      s.total_seconds);
}

}  // namespace

Status Run(const SimulatePaths& paths, const proto::SimulateParams& params, std::ostream* log) {
  const auto wall_start = Clock::now();
  if (paths.out_bag.empty() || paths.out_truth.empty()) {
    return Status::Error("--out_bag and --out_truth are required");
  }
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_bag));
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_truth));
  if (!paths.out_rig.empty()) TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_rig));
  Scenario scenario;
  const Status built = BuildScenario(params, &scenario);
  if (!built.ok()) return paths.params.empty() ? built : built.WithContext(paths.params);
  unsigned threads = params.num_threads();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  ros1::BagWriter writer;
  TILTCAL_RETURN_IF_ERROR(writer.Open(paths.out_bag, ToCompression(params.bag().compression()),
                                      params.bag().chunk_threshold_bytes(), threads));
  const ros1::MessageType& imu_type = ros1::ImuMessageType();
  const ros1::MessageType& cloud_type =
      scenario.scan.model.kind == LidarModel::Kind::kLivox ? ros1::LivoxCustomMsgMessageType()
                                                           : ros1::PointCloud2MessageType();
  const uint32_t imu_conn = writer.AddConnection(params.imu().topic(), imu_type.type,
                                                 imu_type.md5sum, imu_type.definition);
  const uint32_t lidar_conn = writer.AddConnection(params.lidar().topic(), cloud_type.type,
                                                   cloud_type.md5sum, cloud_type.definition);
  TILTCAL_RETURN_IF_ERROR(WriteTfStatic(params, scenario, &writer));

  SimulateSummary summary;
  ImuSimulator imu(params, scenario);
  const TruthFrames frames(params, scenario);
  proto::SimulationTruth truth;
  ScanWriter scans(params, scenario, threads);
  TILTCAL_RETURN_IF_ERROR(scans.WriteAll(BagOutput{&writer, imu_conn, lidar_conn}, &imu, frames,
                                         &truth, cli::IsTerminalLog(log) ? log : nullptr,
                                         &summary));
  TILTCAL_RETURN_IF_ERROR(imu.WriteUpTo(INT64_MAX, imu_conn, &writer));
  TILTCAL_RETURN_IF_ERROR(writer.Close());

  *truth.mutable_provenance() =
      MakeProvenance("tiltcal_simulate", params, {}, paths.command_line);
  FillSequenceTruth(params, scenario, frames, imu, &truth);
  TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out_truth, truth));
  if (!paths.out_rig.empty()) {
    TILTCAL_RETURN_IF_ERROR(WriteTextProto(paths.out_rig, MakeRig(params, scenario, frames)));
  }

  summary.num_imu_samples = scenario.num_imu_samples;
  summary.num_scans = scenario.num_scans - scenario.num_scans_dropped;
  summary.bag_bytes = writer.bytes_written();
  summary.total_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  PrintSummary(log, summary);
  return Status::Ok();
}

}  // namespace tiltcal::simulate
