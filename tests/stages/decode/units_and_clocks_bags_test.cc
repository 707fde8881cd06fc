// The decode stage on bags whose IMU publishes other units or the other sign
// and whose LiDAR stamps on another clock (tests/stages/decode/vehicle_bag.h):
// imu.binpb is always SI, every decision is said, every contradiction is an
// error that leaves no output.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/decode/decode.h"
#include "stages/decode/default_params_text.h"
#include "tests/stages/decode/vehicle_bag.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

class UnitsAndClocks : public ::testing::Test {
 protected:
  void SetUp() override {
    params_ = testing::DefaultParamsWith<proto::DecodeParams>(decode::DefaultParamsText(), "");
  }

  // Writes the bag `name` with `options`; returns its path.
  std::string Bag(const std::string& name, const testing::VehicleBagOptions& options) {
    const std::string path = tmp_.File(name);
    EXPECT_TRUE(testing::WriteVehicleBag(path, options)) << path;
    return path;
  }

  // Writes a rig (identity rotation) with `extra` fields; returns its path.
  std::string Rig(const std::string& extra) {
    const std::string path = tmp_.File("rig.txtpb");
    const proto::Rig rig = testing::ParamsFromText<proto::Rig>(
        "imu_from_lidar { rotation { w: 1 } translation { x: 0.1 } } imu_height_m: 0.3 " + extra);
    EXPECT_TRUE(WriteTextProto(path, rig).ok());
    return path;
  }

  Status Decode(const std::string& bag, const std::string& rig, const std::string& out_dir,
                DecodeSummary* summary) {
    DecodePaths paths;
    paths.bag = bag;
    paths.rig = rig;
    paths.out_imu = out_dir + "/imu.binpb";
    paths.out_scans = out_dir + "/scans.binpb.lz4";
    return ::tiltcal::Decode(paths, params_, /*log=*/nullptr, summary);
  }

  std::string OutDir(const std::string& name) {
    const std::string dir = tmp_.File(name);
    std::filesystem::create_directories(dir);
    return dir;
  }

  void ExpectNoOutput(const std::string& out_dir) {
    EXPECT_TRUE(std::filesystem::is_empty(out_dir)) << "output left behind in " << out_dir;
  }

  static std::string Notes(const DecodeSummary& s) {
    std::string text;
    for (const std::string& note : s.imu_notes) text += note + "\n";
    return text;
  }

  testing::TempDir tmp_;
  proto::DecodeParams params_;
};

// The same motion published in SI and in g and deg/s: AUTO detects both,
// converts the second and writes the same imu.binpb to rounding.
TEST_F(UnitsAndClocks, ImuInGAndDegreesGivesTheSameStreamAsSi) {
  testing::VehicleBagOptions si;
  testing::VehicleBagOptions g_deg;
  g_deg.accel_scale = 1.0 / 9.80665;
  g_deg.gyro_scale = geometry::kDegPerRad;
  const std::string si_out = OutDir("si");
  const std::string g_out = OutDir("g_deg");
  DecodeSummary si_summary, g_summary;
  Status status = Decode(Bag("si.bag", si), "", si_out, &si_summary);
  ASSERT_TRUE(status.ok()) << status.message();
  status = Decode(Bag("g_deg.bag", g_deg), "", g_out, &g_summary);
  ASSERT_TRUE(status.ok()) << status.message();

  EXPECT_EQ(si_summary.accel_to_si, 1.0);
  EXPECT_EQ(si_summary.gyro_to_si, 1.0);
  EXPECT_EQ(g_summary.accel_to_si, 9.80665);
  EXPECT_EQ(g_summary.gyro_to_si, geometry::kRadPerDeg);
  const std::string si_notes = Notes(si_summary);
  const std::string g_notes = Notes(g_summary);
  EXPECT_NE(si_notes.find("accelerometer in m/s², detected: median |f| 9.8089"), std::string::npos)
      << si_notes;
  EXPECT_NE(si_notes.find("static samples; written as published"), std::string::npos)
      << si_notes;
  EXPECT_NE(si_notes.find("gyro in rad/s, assumed: |ω| at percentile 99 is 0.6"),
            std::string::npos)
      << si_notes;
  EXPECT_NE(g_notes.find("accelerometer in g, detected: median |f| 1.000"), std::string::npos)
      << g_notes;
  EXPECT_NE(g_notes.find("converted to m/s² (× 9.80665)"), std::string::npos) << g_notes;
  EXPECT_NE(g_notes.find("gyro in deg/s, detected: |ω| at percentile 99 is 34."),
            std::string::npos)
      << g_notes;
  EXPECT_NE(g_notes.find("above 5 rad/s, the fastest turn of a ground vehicle; converted to "
                         "rad/s (× π/180)"),
            std::string::npos)
      << g_notes;
  EXPECT_NE(g_notes.find("accelerometer sign not checked: without a rig"), std::string::npos)
      << g_notes;

  std::vector<proto::ImuSample> si_imu, g_imu;
  proto::StreamHeader si_header, g_header;
  ASSERT_TRUE(ReadAllRecords<proto::ImuSample>(si_out + "/imu.binpb", &si_imu, &si_header).ok());
  ASSERT_TRUE(ReadAllRecords<proto::ImuSample>(g_out + "/imu.binpb", &g_imu, &g_header).ok());
  ASSERT_EQ(si_imu.size(), g_imu.size());
  ASSERT_EQ(si_imu.size(), 2401u);  // 12 s at 200 Hz
  double worst_relative = 0.0;
  for (size_t i = 0; i < si_imu.size(); ++i) {
    ASSERT_EQ(si_imu[i].stamp_ns(), g_imu[i].stamp_ns());
    const auto& a = si_imu[i];
    const auto& b = g_imu[i];
    const double pairs[6][2] = {
        {a.angular_velocity_radps().x(), b.angular_velocity_radps().x()},
        {a.angular_velocity_radps().y(), b.angular_velocity_radps().y()},
        {a.angular_velocity_radps().z(), b.angular_velocity_radps().z()},
        {a.linear_acceleration_mps2().x(), b.linear_acceleration_mps2().x()},
        {a.linear_acceleration_mps2().y(), b.linear_acceleration_mps2().y()},
        {a.linear_acceleration_mps2().z(), b.linear_acceleration_mps2().z()}};
    for (const auto& pair : pairs) {
      const double relative = std::fabs(pair[0] - pair[1]) / std::max(std::fabs(pair[0]), 1e-300);
      worst_relative = std::max(worst_relative, pair[0] == pair[1] ? 0.0 : relative);
    }
  }
  EXPECT_LT(worst_relative, 1e-14);  // two roundings of a double
  // The decisions are in the provenance of imu.binpb, as said in the log.
  ASSERT_EQ(static_cast<size_t>(g_header.provenance().notes_size()), g_summary.imu_notes.size());
  for (size_t i = 0; i < g_summary.imu_notes.size(); ++i) {
    EXPECT_EQ(g_header.provenance().notes(static_cast<int>(i)), g_summary.imu_notes[i]);
  }
}

// The SI bag's values pass unchanged (bit for bit).
TEST_F(UnitsAndClocks, SiValuesAreWrittenAsPublished) {
  const std::string out = OutDir("out");
  DecodeSummary summary;
  ASSERT_TRUE(Decode(Bag("si.bag", {}), "", out, &summary).ok());
  std::vector<proto::ImuSample> imu;
  ASSERT_TRUE(ReadAllRecords<proto::ImuSample>(out + "/imu.binpb", &imu).ok());
  const std::vector<imu::ImuReading> published = testing::VehicleBagImu(12.0);
  ASSERT_EQ(imu.size(), published.size());
  for (size_t i = 0; i < imu.size(); ++i) {
    ASSERT_EQ(imu[i].angular_velocity_radps().z(), published[i].angular_velocity_radps.z());
    ASSERT_EQ(imu[i].linear_acceleration_mps2().z(), published[i].linear_acceleration_mps2.z());
  }
}

TEST_F(UnitsAndClocks, UnitsStatedByTheRigAndConsistent) {
  testing::VehicleBagOptions g_deg;
  g_deg.accel_scale = 1.0 / 9.80665;
  g_deg.gyro_scale = geometry::kDegPerRad;
  DecodeSummary summary;
  const Status status = Decode(Bag("g_deg.bag", g_deg),
                               Rig("imu_accel_unit: G imu_gyro_unit: DEGPS"), OutDir("out"),
                               &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(summary.accel_to_si, 9.80665);
  EXPECT_EQ(summary.gyro_to_si, geometry::kRadPerDeg);
  const std::string notes = Notes(summary);
  EXPECT_NE(notes.find("accelerometer in g, stated by the rig (imu_accel_unit: G) and "
                       "consistent with median |f| 1.000"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("gyro in deg/s, stated by the rig (imu_gyro_unit: DEGPS)"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("accelerometer sign checked: the mean specific force over"),
            std::string::npos)
      << notes;
  EXPECT_TRUE(summary.imu_warnings.empty());
}

TEST_F(UnitsAndClocks, RigStatingTheWrongAccelerometerUnitIsAnError) {
  testing::VehicleBagOptions g;
  g.accel_scale = 1.0 / 9.80665;
  const std::string bag = Bag("g.bag", g);
  const std::string rig = Rig("imu_accel_unit: MPS2");
  const std::string out = OutDir("out");
  DecodeSummary summary;
  const Status status = Decode(bag, rig, out, &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind(rig + ": imu_accel_unit is MPS2 but the accelerometer of " +
                                       bag + " reads in g: median |f| 1.000",
                                   0),
            0u)
      << status.message();
  ExpectNoOutput(out);
}

TEST_F(UnitsAndClocks, RigStatingRadiansForADegreeGyroIsAnError) {
  testing::VehicleBagOptions deg;
  deg.gyro_scale = geometry::kDegPerRad;
  const std::string bag = Bag("deg.bag", deg);
  const std::string rig = Rig("imu_gyro_unit: RADPS");
  const std::string out = OutDir("out");
  DecodeSummary summary;
  const Status status = Decode(bag, rig, out, &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind(rig + ": imu_gyro_unit is RADPS but the gyro of " + bag +
                                       " reads in deg/s: |ω| at percentile 99 is 34.",
                                   0),
            0u)
      << status.message();
  ExpectNoOutput(out);
}

// A deg/s statement cannot be contradicted by slow rates: accepted.
TEST_F(UnitsAndClocks, DegreesStatedForASlowGyroIsAccepted) {
  DecodeSummary summary;
  const Status status =
      Decode(Bag("si.bag", {}), Rig("imu_gyro_unit: DEGPS"), OutDir("out"), &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(summary.gyro_to_si, geometry::kRadPerDeg);
}

TEST_F(UnitsAndClocks, AccelerometerFittingNeitherUnitIsAnError) {
  testing::VehicleBagOptions odd;
  odd.accel_scale = 3.7 / 9.81;  // |f| 3.7 at rest
  const std::string bag = Bag("odd.bag", odd);
  const std::string out = OutDir("out");
  DecodeSummary summary;
  const Status status = Decode(bag, "", out, &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind(
                bag + ": the accelerometer fits neither m/s² nor g: median |f| 3.699", 0),
            0u)
      << status.message();
  EXPECT_NE(status.message().find("imu_units.accel_norm_ratio_min/max"), std::string::npos);
  ExpectNoOutput(out);
}

// A sample no vehicle IMU can report (1e300 m/s², or 1000 rad/s) is the
// corrupt record it is: an error naming the sample, no output. Before the
// range check, 1e300 m/s² passed decode, ground and gravity and calibrate
// blamed the rig rotation.
TEST_F(UnitsAndClocks, ImuSampleBeyondAnyPhysicalRangeIsAnError) {
  for (const auto& [accel_mps2, gyro_radps, quantity] :
       {std::tuple{1e300, 0.0, "|linear acceleration| 1e+300 m/s²"},
        std::tuple{-450.0, 0.0, "|linear acceleration| 450"},
        std::tuple{0.0, 1000.0, "|angular velocity| 1000 rad/s"}}) {
    testing::VehicleBagOptions corrupt;
    corrupt.corrupt_imu_index = 700;
    corrupt.corrupt_accel_mps2 = accel_mps2;
    corrupt.corrupt_gyro_radps = gyro_radps;
    const std::string bag = Bag("corrupt.bag", corrupt);
    const std::string out = OutDir("out_corrupt");
    DecodeSummary summary;
    const Status status = Decode(bag, "", out, &summary);
    ASSERT_FALSE(status.ok()) << quantity;
    EXPECT_EQ(status.message().rfind(bag + ": IMU sample 700 in stamp order", 0), 0u)
        << status.message();
    EXPECT_NE(status.message().find(quantity), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("a corrupt record"), std::string::npos) << status.message();
    ExpectNoOutput(out);
  }
  // The largest accepted readings decode.
  testing::VehicleBagOptions hard;
  hard.corrupt_imu_index = 700;
  hard.corrupt_accel_mps2 = 390.0;
  hard.corrupt_gyro_radps = 69.0;
  DecodeSummary summary;
  EXPECT_TRUE(Decode(Bag("hard.bag", hard), "", OutDir("out_hard"), &summary).ok());
}

// Two decodes of one bag into the same outputs at once: the second waits for
// the first's lock on the output folder, so both succeed and leave one
// consistent pair and no commit manifest (without the lock, one failed on
// the other's manifests after the outputs were in place).
TEST_F(UnitsAndClocks, TwoDecodesOfTheSameOutputsAtOnceBothSucceed) {
  const std::string bag = Bag("vehicle.bag", testing::VehicleBagOptions{});
  const std::string out = OutDir("out_twice");
  for (int trial = 0; trial < 5; ++trial) {
    Status statuses[2];
    DecodeSummary summaries[2];
    std::thread other([&] { statuses[1] = Decode(bag, "", out, &summaries[1]); });
    statuses[0] = Decode(bag, "", out, &summaries[0]);
    other.join();
    for (const Status& status : statuses) EXPECT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(summaries[0].imu_written, summaries[1].imu_written);
    std::vector<std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(out)) {
      files.push_back(entry.path().filename().string());
    }
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files, (std::vector<std::string>{"imu.binpb", "scans.binpb.lz4"})) << trial;
    RecordReader reader;
    ASSERT_TRUE(reader.Open(out + "/imu.binpb").ok());
    proto::ImuSample sample;
    int64_t samples = 0;
    bool end = false;
    while (reader.Read(&sample, &end).ok() && !end) ++samples;
    EXPECT_EQ(samples, summaries[0].imu_written);
  }
}

// Specific force pointing down at rest, against the rig's g_f: an error.
TEST_F(UnitsAndClocks, SignFlippedAccelerometerAgainstGravityFlatIsAnError) {
  testing::VehicleBagOptions flipped;
  flipped.accel_scale = -1.0;
  const std::string bag = Bag("flipped.bag", flipped);
  const std::string rig = Rig("gravity_flat_in_imu { z: -9.81 }");
  const std::string out = OutDir("out");
  DecodeSummary summary;
  const Status status = Decode(bag, rig, out, &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind(rig + ": the mean specific force over ", 0), 0u)
      << status.message();
  EXPECT_NE(status.message().find("points 180.0 deg from up (−gravity_flat_in_imu of the rig; "
                                  "more than 90): the accelerometer of " +
                                  bag + " publishes gravity instead of specific force"),
            std::string::npos)
      << status.message();
  ExpectNoOutput(out);
  // The same bag with the right sign passes the check.
  ASSERT_TRUE(Decode(Bag("si.bag", {}), rig, out, &summary).ok());
  EXPECT_NE(Notes(summary).find("points 0.0 deg from up (−gravity_flat_in_imu of the rig)"),
            std::string::npos)
      << Notes(summary);
}

// Without g_f the rig's rotation (LiDAR +z) is the reference: a warning, as
// the rig's rotation may be what is wrong; the data are written as published.
TEST_F(UnitsAndClocks, SignFlippedAccelerometerAgainstTheLidarUpIsAWarning) {
  testing::VehicleBagOptions flipped;
  flipped.accel_scale = -1.0;
  const std::string out = OutDir("out");
  DecodeSummary summary;
  const Status status = Decode(Bag("flipped.bag", flipped), Rig(""), out, &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(summary.imu_warnings.size(), 1u);
  EXPECT_NE(summary.imu_warnings[0].find(
                "points 180.0 deg from the LiDAR's +z (through imu_from_lidar of the rig; more "
                "than 90): the accelerometer publishes gravity instead of specific force "
                "(sign-flipped), or the rig's rotation is wrong"),
            std::string::npos)
      << summary.imu_warnings[0];
  std::vector<proto::ImuSample> imu;
  proto::StreamHeader header;
  ASSERT_TRUE(ReadAllRecords<proto::ImuSample>(out + "/imu.binpb", &imu, &header).ok());
  EXPECT_LT(imu[0].linear_acceleration_mps2().z(), -9.0);
  bool in_provenance = false;
  for (const std::string& note : header.provenance().notes()) {
    in_provenance |= note == summary.imu_warnings[0];
  }
  EXPECT_TRUE(in_provenance);
}

// LiDAR stamps 10 min after the IMU's (another clock): one error naming
// both spans and the field, with the shift the record times suggest.
TEST_F(UnitsAndClocks, ClockDomainsTenMinutesApartAreAnError) {
  testing::VehicleBagOptions late;
  late.lidar_stamp_offset_ns = 600LL * 1000000000LL;
  const std::string bag = Bag("late.bag", late);
  const std::string out = OutDir("out");
  DecodeSummary summary;
  Status status = Decode(bag, "", out, &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            bag + ": the LiDAR and IMU stamps do not overlap (two clocks?): IMU stamps "
                  "1700000000.000 .. 1700000012.000 s (2023-11-14 22:13:20 UTC .. 2023-11-14 "
                  "22:13:32 UTC), LiDAR stamps 1700000600.000 .. 1700000611.900 s (2023-11-14 "
                  "22:23:20 UTC .. 2023-11-14 22:23:31 UTC), the LiDAR 588.000 s after the IMU; "
                  "set lidar_stamp_shift_s in the decode params (added to every LiDAR stamp, s) "
                  "to decode anyway: the bag's record times suggest lidar_stamp_shift_s: "
                  "-599.981");
  ExpectNoOutput(out);

  // With the shift the bag decodes; the LiDAR stamps are on the IMU clock.
  params_.set_lidar_stamp_shift_s(-600.0);
  status = Decode(bag, "", out, &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(summary.scan_first_stamp_ns, testing::kVehicleBagStartNs);
  EXPECT_NEAR(summary.stamp_overlap_s, 11.9, 1e-9);
  std::vector<proto::Scan> scans;
  ASSERT_TRUE(ReadAllRecords<proto::Scan>(out + "/scans.binpb.lz4", &scans).ok());
  EXPECT_EQ(scans.front().stamp_ns(), testing::kVehicleBagStartNs);
  EXPECT_EQ(scans.front().record_stamp_ns(),
            testing::kVehicleBagStartNs + testing::kVehicleBagLidarLatencyNs);
}

// A LiDAR on its own clock since power-on (stamps near 1970): years apart.
TEST_F(UnitsAndClocks, ClockDomainsYearsApartNameTheDates) {
  testing::VehicleBagOptions boot_time;
  boot_time.lidar_stamp_offset_ns = 1000LL * 1000000000LL - testing::kVehicleBagStartNs;
  const std::string bag = Bag("boot.bag", boot_time);
  DecodeSummary summary;
  const Status status = Decode(bag, "", OutDir("out"), &summary);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("LiDAR stamps 1000.000 .. 1011.900 s (1970-01-01 00:16:40 UTC"),
            std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("s before the IMU"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("suggest lidar_stamp_shift_s: 1699999000.019"),
            std::string::npos)
      << status.message();
}

// Stamps that overlap in part are the calibration's business: decoded.
// A LiDAR clock 100 ppm fast: 1.2 ms of τ over the 12 s, said on stderr and
// in imu.binpb's provenance; the same bag without drift says nothing.
TEST_F(UnitsAndClocks, LidarClockDriftIsMeasuredAndSaid) {
  for (const double ppm : {0.0, 100.0}) {
    testing::VehicleBagOptions options;
    options.lidar_clock_drift_ppm = ppm;
    const std::string name = ppm == 0.0 ? "steady" : "drift";
    const std::string out = OutDir(name);
    DecodeSummary summary;
    const Status status = Decode(Bag(name + ".bag", options), "", out, &summary);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(summary.lidar_clock_vs_imu.measured);
    EXPECT_NEAR(summary.lidar_clock_vs_imu.rate_ppm, ppm, 1.0);
    EXPECT_NEAR(summary.lidar_clock_vs_imu.time_offset_drift_s, ppm * 1e-6 * summary.stamp_overlap_s,
                2e-5);
    RecordReader reader;
    ASSERT_TRUE(reader.Open(out + "/imu.binpb").ok());
    bool said = false;
    for (const std::string& note : reader.header().provenance().notes()) {
      said = said || note.find("ppm against the IMU's") != std::string::npos;
    }
    EXPECT_EQ(said, ppm > 0.0) << summary.clock_drift_note;
    EXPECT_EQ(summary.clock_drift_note.empty(), ppm == 0.0);
  }
}

TEST_F(UnitsAndClocks, PartialOverlapDecodes) {
  testing::VehicleBagOptions offset;
  offset.lidar_stamp_offset_ns = 9LL * 1000000000LL;  // 9 s of the LiDAR's 12 past the IMU's end
  DecodeSummary summary;
  const Status status = Decode(Bag("offset.bag", offset), "", OutDir("out"), &summary);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_NEAR(summary.stamp_overlap_s, 3.0, 1e-9);
}

}  // namespace
}  // namespace tiltcal
