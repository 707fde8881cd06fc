#include "stages/inspect/inspect.h"

#include <filesystem>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/inspect/csv_table.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/gravity.pb.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::inspect {
namespace {

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

template <typename T>
void WriteStream(const std::string& path, const std::vector<T>& records, bool compress) {
  RecordWriter writer;
  ASSERT_TRUE(writer.Open(path, T::descriptor()->full_name(), {}, compress).ok());
  for (const T& record : records) ASSERT_TRUE(writer.Write(record).ok());
  ASSERT_TRUE(writer.Close().ok());
}

std::vector<proto::GroundPlane> SomePlanes() {
  std::vector<proto::GroundPlane> planes(3);
  for (int i = 0; i < 3; ++i) {
    planes[i].set_stamp_ns(1000 + i);
    planes[i].set_valid(i != 1);
    planes[i].mutable_normal_in_lidar()->set_z(0.1 * (i + 1));
    planes[i].set_height_m(1.0 / 3.0 + i);
    if (i == 1) planes[i].set_reject_reason(proto::GROUND_HIGH_RMS);
  }
  return planes;
}

TEST(InspectCsv, GroundPlanesGiveDottedHeaderAndExactValues) {
  testing::TempDir dir;
  WriteStream(dir.File("ground.binpb"), SomePlanes(), false);
  std::ostringstream out;
  ASSERT_TRUE(RunCsv(dir.File("ground.binpb"), {}, out).ok());
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0].rfind("stamp_ns,valid,normal_in_lidar.x,normal_in_lidar.y,normal_in_lidar.z,"
                           "height_m,",
                           0),
            0u)
      << lines[0];
  EXPECT_EQ(lines[1].rfind("1000,1,0,0,0.1,0.3333333333333333,", 0), 0u) << lines[1];
  EXPECT_NE(lines[2].find("GROUND_HIGH_RMS"), std::string::npos) << lines[2];
  EXPECT_EQ(lines[2].rfind("1001,0,", 0), 0u);
  // Repeated fields (covariance) are not columns.
  EXPECT_EQ(lines[0].find("covariance"), std::string::npos);
}

TEST(InspectCsv, ScanStreamHasNumPointsAndPointsOfOneRecord) {
  testing::TempDir dir;
  std::vector<proto::Scan> scans(2);
  for (int s = 0; s < 2; ++s) {
    scans[s].set_index(s);
    scans[s].set_stamp_ns(5'000'000'000LL + s);
    for (int i = 0; i < 3 + s; ++i) {
      scans[s].add_x(i + 0.5f);
      scans[s].add_y(-i);
      scans[s].add_z(0.25f);
      scans[s].add_intensity(7);
      scans[s].add_ring(i);
      scans[s].add_time_offset_ns(-1000 * i);
    }
  }
  WriteStream(dir.File("scans.binpb.lz4"), scans, true);
  std::ostringstream table;
  ASSERT_TRUE(RunCsv(dir.File("scans.binpb.lz4"), {}, table).ok());
  auto lines = Lines(table.str());
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("index,stamp_ns,", 0), 0u) << lines[0];
  EXPECT_EQ(lines[0].substr(lines[0].size() - 11), ",num_points");
  EXPECT_EQ(lines[2].substr(lines[2].size() - 2), ",4");

  std::ostringstream points;
  ASSERT_TRUE(RunCsv(dir.File("scans.binpb.lz4"), {true, 1, ""}, points).ok());
  lines = Lines(points.str());
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], "x,y,z,intensity,ring,time_offset_ns");
  EXPECT_EQ(lines[3], "2.5,-2,0.25,7,2,-2000");

  std::ostringstream missing;
  const Status status = RunCsv(dir.File("scans.binpb.lz4"), {true, 9, ""}, missing);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no record 9"), std::string::npos);
}

TEST(InspectCsv, TextFileTabulatesItsRepeatedField) {
  testing::TempDir dir;
  proto::GravityReference gravity;
  gravity.mutable_gravity_flat_in_imu()->set_z(-9.81);
  gravity.add_static_windows()->set_begin_ns(7);  // shorter list: not the default table
  for (int i = 0; i < 4; ++i) {
    auto* sample = gravity.add_inclination();
    sample->set_stamp_ns(i);
    sample->set_inclination_deg(0.5 * i);
  }
  ASSERT_TRUE(WriteTextProto(dir.File("gravity.txtpb"), gravity).ok());
  std::ostringstream out;
  ASSERT_TRUE(RunCsv(dir.File("gravity.txtpb"), {}, out).ok());
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0],
            "stamp_ns,inclination_deg,up_in_imu.x,up_in_imu.y,up_in_imu.z,ground_slope_deg");
  EXPECT_EQ(lines[4], "3,1.5,0,0,0,");  // unknown slope: empty cell

  std::ostringstream windows;
  ASSERT_TRUE(RunCsv(dir.File("gravity.txtpb"), {false, 0, "static_windows"}, windows).ok());
  EXPECT_EQ(Lines(windows.str()).size(), 2u);
}

TEST(InspectInfo, CountsRecordsReasonsAndSpan) {
  testing::TempDir dir;
  WriteStream(dir.File("ground.binpb"), SomePlanes(), true);
  std::ostringstream out;
  ASSERT_TRUE(RunInfo(dir.File("ground.binpb"), out).ok());
  const std::string text = out.str();
  EXPECT_NE(text.find("record stream: tiltcal.proto.GroundPlane"), std::string::npos) << text;
  EXPECT_NE(text.find("records: 3"), std::string::npos) << text;
  EXPECT_NE(text.find("stamps: 1000 .. 1002 ns"), std::string::npos) << text;
  EXPECT_NE(text.find("ground: GROUND_HIGH_RMS x1"), std::string::npos) << text;
  EXPECT_NE(text.find("ground: GROUND_OK x2"), std::string::npos) << text;
}

TEST(InspectCat, SingleLineGivesOneLinePerRecordInRange) {
  testing::TempDir dir;
  WriteStream(dir.File("ground.binpb"), SomePlanes(), false);
  std::ostringstream out;
  ASSERT_TRUE(RunCat(dir.File("ground.binpb"), {1, 1, true}, out).ok());
  const auto lines = Lines(out.str());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("stamp_ns: 1001"), std::string::npos) << lines[0];
}

TEST(InspectCli, BadFileIsOneErrorLineAndNonZeroExit) {
  testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir.File("junk.binpb"), "not a proto { at all").ok());
  std::string output;
  const int code = testing::RunCommand(
      testing::ToolPath("tiltcal_inspect") + " info " + dir.File("junk.binpb"), &output);
  EXPECT_EQ(code, 1);
  EXPECT_EQ(Lines(output).size(), 1u) << output;
  EXPECT_NE(output.find(dir.File("junk.binpb")), std::string::npos) << output;
}

// `> ground.csv` on a full disk: the table is cut short, so the exit is 1
// with one line naming standard output (the Makefile builds ground.csv so).
TEST(InspectCli, StdoutThatCannotBeWrittenIsAFailure) {
  testing::TempDir dir;
  WriteStream(dir.File("ground.binpb"), SomePlanes(), false);
  for (const char* command : {" csv ", " cat "}) {
    std::string output;
    const int code = testing::RunCommand(
        "{ " + testing::ToolPath("tiltcal_inspect") + command + dir.File("ground.binpb") +
            " > /dev/full; }",
        &output);
    EXPECT_EQ(code, 1) << command << output;
    EXPECT_EQ(Lines(output).size(), 1u) << output;
    EXPECT_NE(output.find("standard output: cannot write: No space left on device"),
              std::string::npos)
        << output;
  }
}

// A PCD on a full disk (here: a file size limit of 512 bytes, with SIGXFSZ
// ignored so that the write fails with EFBIG as it would with ENOSPC): one
// error line naming the PCD, exit 1, neither the PCD nor a temporary left.
TEST(InspectCli, PcdOnAFullDiskIsAnErrorAndLeavesNothing) {
  testing::TempDir dir;
  std::vector<proto::Scan> scans(1);
  for (int i = 0; i < 100; ++i) {  // 100 points × 25 bytes: over the limit
    scans[0].add_x(i + 1.0f);
    scans[0].add_y(0);
    scans[0].add_z(0);
    scans[0].add_intensity(1);
    scans[0].add_ring(0);
    scans[0].add_time_offset_ns(0);
  }
  WriteStream(dir.File("scans.binpb.lz4"), scans, true);
  const std::string pcd = dir.File("scan0.pcd");
  std::string output;
  const int code = testing::RunCommand("sh -c \"trap '' XFSZ; ulimit -f 1; exec " +
                                           testing::ToolPath("tiltcal_inspect") + " pcd " +
                                           dir.File("scans.binpb.lz4") + " --out=" + pcd + "\"",
                                       &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_EQ(Lines(output).size(), 1u) << output;
  EXPECT_NE(output.find(pcd + ": cannot write output"), std::string::npos) << output;
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1)
      << "only the scans stay";
  // Without the limit the same command writes the PCD.
  ASSERT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_inspect") + " pcd " +
                                    dir.File("scans.binpb.lz4") + " --out=" + pcd,
                                &output),
            0)
      << output;
  EXPECT_TRUE(testing::FileExists(pcd));
}

TEST(FormatDouble, ShortestRoundTrip) {
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(std::stod(FormatDouble(1.0 / 3.0)), 1.0 / 3.0);
  EXPECT_EQ(FormatDouble(-9.81), "-9.81");
}

}  // namespace
}  // namespace tiltcal::inspect
