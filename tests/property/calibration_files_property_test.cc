// Property test: random and hostile calibration.txtpb files (NaN, Inf, huge
// and tiny numbers, non-unit quaternions, missing fields, indefinite, zero,
// asymmetric and ill-conditioned covariances, sequences that disagree,
// random verdicts, gravities that are no gravity) through the four binaries
// that read them. For every run:
//   - no crash: the exit code is one the program documents (0 done, 1 failed,
//     2 usage, 3 SUSPECT for tiltcal_dataset_calibration);
//   - exit 1 or 2 leaves no output;
//   - a written output holds only finite numbers;
//   - exit 0 only with a verdict the inputs allow: tiltcal_dataset_calibration
//     uses only files that are whole (generated valid) and OK or WEAK, and the
//     sequences it uses come from one group (never two that disagree);
//     tiltcal_gravity_reference's g_f and every used g_a lie in the norm
//     bounds and within its angle of each other; tiltcal_export refuses
//     SUSPECT; tiltcal_report and tiltcal_export print no nan or inf.
// Each case is generated from its own seed (std::mt19937), so a failure names
// the seed that reproduces it.
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "common/geometry/angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/gravity.pb.h"

namespace tiltcal {
namespace {

constexpr int kCases = 40;
using geometry::kDegPerRad;
// The defaults of the programs under test (stages/*/default_params.txtpb).
constexpr double kMinGravityNorm = 9.7, kMaxGravityNorm = 9.9;
constexpr double kMaxGravityAngleDeg = 0.3;

// What the generator made of a file.
enum class Kind {
  kGood,        // whole, drawn from its group's covariance
  kHostile,     // broken one way or another: must never be used
  kUnreadable,  // not a calibration in text format: the run is an error
};

struct GeneratedSequence {
  std::string name;
  std::string dir;
  Kind kind = Kind::kGood;
  int group = 0;  // sequences of different groups disagree by far more than their sigma
  std::string mutation;
  proto::CalibrationResult result;
  std::string text;  // the file as written (kUnreadable: broken text)
};

class Generator {
 public:
  explicit Generator(unsigned seed) : rng_(seed) {}

  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  int Pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }
  double Normal() { return std::normal_distribution<double>()(rng_); }

  // A number no calibration holds.
  double HostileNumber() {
    static const double kValues[] = {std::numeric_limits<double>::quiet_NaN(),
                                     std::numeric_limits<double>::infinity(),
                                     -std::numeric_limits<double>::infinity(), 1e300, -1e300};
    return kValues[Pick(5)];
  }

  // Draws in named variables: the order of a constructor's arguments is the
  // compiler's (tests/testing/random_vector.h).
  Eigen::Quaterniond RandomRotation() {
    const double w = Normal(), x = Normal(), y = Normal(), z = Normal();
    return Eigen::Quaterniond(w, x, y, z).normalized();
  }
  Eigen::Vector3d UniformVector(double lo, double hi) {
    const double x = Uniform(lo, hi), y = Uniform(lo, hi), z = Uniform(lo, hi);
    return Eigen::Vector3d(x, y, z);
  }

  // One dataset: a truth, up to two groups (the second far from the first),
  // each sequence's value drawn from its covariance.
  std::vector<GeneratedSequence> Dataset(const std::string& root) {
    const int count = 1 + Pick(4);
    Rigid3d truth[2];
    truth[0].rotation = RandomRotation();
    truth[0].translation = UniformVector(-1, 1);
    truth[1] = truth[0];
    if (Chance(0.5)) {
      const double angle_deg = Uniform(5, 180);
      const Eigen::Vector3d axis = RandomRotation().vec().normalized();
      truth[1].rotation = truth[0].rotation * Eigen::AngleAxisd(angle_deg / kDegPerRad, axis);
    } else {
      const double distance_m = Uniform(0.3, 1.0);
      truth[1].translation += distance_m * RandomRotation().vec().normalized();
    }
    const bool two_groups = Chance(0.4);
    const double gx = Uniform(-0.1, 0.1), gy = Uniform(-0.1, 0.1);
    const Eigen::Vector3d g0 = 9.81 * Eigen::Vector3d(gx, gy, -1).normalized();
    std::vector<GeneratedSequence> sequences(count);
    for (int i = 0; i < count; ++i) {
      GeneratedSequence& s = sequences[i];
      s.name = "seq" + std::to_string(i);
      s.dir = root + "/" + s.name;
      s.group = two_groups ? Pick(2) : 0;
      s.result = Whole(truth[s.group], g0);
      if (Chance(0.35)) {
        s.kind = Kind::kHostile;
        s.mutation = Break(&s.result);
      }
      if (Chance(0.2)) s.mutation += BreakGravity(&s.result, g0);
      EXPECT_TRUE(TextOf(s.result, &s.text));
      if (Chance(0.06)) {
        s.kind = Kind::kUnreadable;
        s.mutation += BreakText(&s.text);
      }
    }
    return sequences;
  }

 private:
  // A whole calibration near `truth` with a diagonal covariance of random
  // realistic sigmas and an error drawn from it.
  proto::CalibrationResult Whole(const Rigid3d& truth, const Eigen::Vector3d& g0) {
    Eigen::Matrix<double, 7, 1> sigma;
    for (int k = 0; k < 3; ++k) sigma[k] = Uniform(0.002, 0.2) / kDegPerRad;
    for (int k = 3; k < 6; ++k) sigma[k] = Uniform(0.001, 0.02);
    sigma[6] = Uniform(1e-5, 1e-3);
    Eigen::Matrix<double, 7, 1> e;
    for (int k = 0; k < 7; ++k) e[k] = sigma[k] * Normal();
    proto::CalibrationResult r;
    Rigid3d x = truth;
    x.rotation = (truth.rotation * Eigen::AngleAxisd(e.head<3>().norm(), e.head<3>().normalized()))
                     .normalized();
    x.translation += e.segment<3>(3);
    *r.mutable_imu_from_lidar() = ToProto(x);
    Rigid3d rig = truth;
    rig.translation += Eigen::Vector3d(0.02, -0.01, 0.03);
    *r.mutable_rig_imu_from_lidar() = ToProto(rig);
    r.set_time_offset_s(0.01 + e[6]);
    r.set_time_offset_sigma_s(sigma[6]);
    for (int i = 0; i < 7; ++i) {
      for (int j = 0; j < 7; ++j) r.add_covariance(i == j ? sigma[i] * sigma[i] : 0.0);
    }
    r.set_verdict(Chance(0.5) ? proto::CalibrationResult::OK : proto::CalibrationResult::WEAK);
    *r.mutable_motion_rotation_axis_b() = ToProto(Eigen::Vector3d(0, 0, 1));
    const double angle = Uniform(0.0, 0.02) / kDegPerRad;
    const double scale = Uniform(0.995, 1.005);
    *r.mutable_gravity_in_world() =
        ToProto(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()) * g0 * scale);
    r.set_static_start(true);
    r.add_ground_residuals_used("flat");
    return r;
  }

  static bool TextOf(const proto::CalibrationResult& r, std::string* text) {
    return google::protobuf::TextFormat::PrintToString(r, text);
  }

  // A g_a that is no gravity or not the others' (the dataset calibration
  // does not read it).
  std::string BreakGravity(proto::CalibrationResult* r, const Eigen::Vector3d& g0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double angle_deg = Uniform(1, 179);
    const Eigen::Vector3d values[] = {
        -g0,
        Eigen::AngleAxisd(angle_deg / kDegPerRad, Eigen::Vector3d::UnitX()) * g0,
        g0.normalized() * 1.5,
        g0.normalized() * 1e300,
        Eigen::Vector3d(nan, 0, 9.81),
        Eigen::Vector3d::Zero(),
        g0.normalized() * 1e-300,
        g0.normalized() * 9.6};
    *r->mutable_gravity_in_world() = ToProto(values[Pick(8)]);
    return " gravity hostile";
  }

  // Text that does not parse as a calibration, or gives a field twice.
  std::string BreakText(std::string* text) {
    switch (Pick(4)) {
      case 0:
        *text = "time_offset_s: 0\n" + *text;
        return " a field twice";
      case 1:
        text->clear();
        return " empty file";
      case 2:
        text->resize(text->size() / 2);
        return " cut in half";
      default:
        *text += "\nno_such_field: 1\n";
        return " unknown field";
    }
  }

  // Breaks `r` one way; returns how.
  std::string Break(proto::CalibrationResult* r) {
    proto::Quaternion* q = r->mutable_imu_from_lidar()->mutable_rotation();
    const int covariance_entry = Pick(49);
    switch (Pick(16)) {
      case 0:
        q->set_w(HostileNumber());
        return "quaternion w hostile";
      case 1:
        r->clear_imu_from_lidar();
        return "no imu_from_lidar";
      case 2: {
        const bool longer = Chance(0.5);
        const double f = longer ? Uniform(1.01, 3.0) : Uniform(0.1, 0.99);
        q->set_w(q->w() * f);
        q->set_x(q->x() * f);
        q->set_y(q->y() * f);
        q->set_z(q->z() * f);
        return "non-unit quaternion";
      }
      case 3:
        r->mutable_imu_from_lidar()->mutable_translation()->set_y(Chance(0.5) ? std::nan("")
                                                                              : -HUGE_VAL);
        return "translation non-finite";
      case 4:
        r->set_time_offset_s(Chance(0.5) ? std::nan("") : HUGE_VAL);
        return "tau non-finite";
      case 5:
        r->set_time_offset_sigma_s(Chance(0.5) ? std::nan("") : -1.0);
        return "tau sigma non-finite or negative";
      case 6:
        for (int k = 0; k < 49; ++k) r->set_covariance(k, 0.0);
        return "covariance zero";
      case 7:
        for (int k = 0; k < 49; ++k) r->set_covariance(k, -r->covariance(k));
        return "covariance negative definite";
      case 8: {
        const double f = Chance(0.5) ? 1e-300 : 1e300;
        for (int k = 0; k < 49; ++k) r->set_covariance(k, r->covariance(k) * f);
        return "covariance scaled by 1e+-300";
      }
      case 9:
        r->set_covariance(covariance_entry, Chance(0.5) ? std::nan("") : HUGE_VAL);
        return "covariance entry non-finite";
      case 10: {
        // Asymmetric: one off-diagonal entry without its mirror.
        const int i = Pick(6);
        const int j = (i + 1 + Pick(5)) % 6;
        r->set_covariance(i * 7 + j,
                          10.0 * std::sqrt(r->covariance(i * 7 + i) * r->covariance(j * 7 + j)));
        return "covariance asymmetric";
      }
      case 11: {
        // Indefinite: a correlation above 1 between two components.
        const int i = Pick(6);
        const int j = (i + 1 + Pick(5)) % 6;
        const double c = 3.0 * std::sqrt(r->covariance(i * 7 + i) * r->covariance(j * 7 + j));
        r->set_covariance(i * 7 + j, c);
        r->set_covariance(j * 7 + i, c);
        return "covariance indefinite";
      }
      case 12:
        r->mutable_covariance()->Truncate(Pick(49));
        return "covariance short";
      case 13:
        r->set_covariance(0, 1e-30);
        r->set_covariance(8, 1e6);
        return "covariance ill-conditioned";
      case 14:
        r->clear_rig_imu_from_lidar();
        return "no rig_imu_from_lidar";
      default: {
        const int verdicts[] = {0, 3, 7, -2};
        r->set_verdict(static_cast<proto::CalibrationResult::Verdict>(verdicts[Pick(4)]));
        return "verdict not OK or WEAK";
      }
    }
  }

  std::mt19937 rng_;
};

bool Finite(const proto::Vector3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

bool AllFinite(const proto::CalibrationResult& r) {
  const auto& q = r.imu_from_lidar().rotation();
  bool finite = std::isfinite(q.w()) && std::isfinite(q.x()) && std::isfinite(q.y()) &&
                std::isfinite(q.z()) && Finite(r.imu_from_lidar().translation()) &&
                std::isfinite(r.time_offset_s()) && std::isfinite(r.time_offset_sigma_s()) &&
                Finite(r.rotation_sigma_deg()) && Finite(r.translation_sigma_m());
  for (double v : r.covariance()) finite = finite && std::isfinite(v);
  for (const proto::DatasetSequence& s : r.sequences()) {
    finite = finite && std::isfinite(s.consistency_chi2()) && std::isfinite(s.consistency_limit());
  }
  return finite;
}

// A word nan or inf (any case) in a program's text.
bool HasNonFiniteWord(const std::string& text) {
  static const std::regex kWord("(^|[^A-Za-z0-9_])(-?)(nan|inf|infinity)($|[^A-Za-z0-9_])",
                                std::regex::icase);
  return std::regex_search(text, kWord);
}

// `text` without the verdict reasons of `calibrations` (quoted by exports and
// the report: a reason may name a refused input's value, "tau = inf").
std::string WithoutReasons(std::string text, const std::vector<std::string>& calibrations) {
  for (const std::string& path : calibrations) {
    proto::CalibrationResult r;
    if (!ReadTextProto(path, &r).ok()) continue;
    for (const std::string& reason : r.verdict_reasons()) {
      for (size_t at = text.find(reason); !reason.empty() && at != std::string::npos;
           at = text.find(reason)) {
        text.erase(at, reason.size());
      }
    }
  }
  return text;
}

std::string ReadText(const std::string& path) {
  std::string text;
  EXPECT_TRUE(ReadFileToString(path, &text).ok()) << path;
  return text;
}

// Exit codes seen per program, printed at the end: the cases reach every
// outcome (a change of the generator that stops doing so shows there).
std::map<std::string, std::map<int, int>>& ExitCounts() {
  static std::map<std::string, std::map<int, int>> counts;
  return counts;
}

// The exit code of `command`; a crash (signal) or an undocumented code fails.
int Run(const std::string& command, const std::vector<int>& documented, std::string* output) {
  const int code = testing::RunCommand(command, output);
  const std::string program =
      std::filesystem::path(command.substr(0, command.find(' '))).filename();
  ++ExitCounts()[program][code];
  EXPECT_NE(std::find(documented.begin(), documented.end(), code), documented.end())
      << "exit " << code << " of " << command << "\n"
      << *output;
  return code;
}

void CheckDatasetCalibration(const std::vector<GeneratedSequence>& sequences,
                             const std::string& root, std::string* dataset_out) {
  std::string command =
      testing::ToolPath("tiltcal_dataset_calibration") + " --out=" + root + "/calibration.txtpb";
  for (const GeneratedSequence& s : sequences) command += " " + s.dir + "/calibration.txtpb";
  std::string output;
  const int code = Run(command, {0, 1, 3}, &output);
  const bool written = testing::FileExists(root + "/calibration.txtpb");
  int whole_usable = 0;
  bool unreadable = false;
  for (const GeneratedSequence& s : sequences) {
    whole_usable += s.kind == Kind::kGood;
    unreadable |= s.kind == Kind::kUnreadable;
  }
  if (code == 1) {
    EXPECT_FALSE(written) << output;
    // A whole OK or WEAK sequence is always usable: there is a result.
    EXPECT_TRUE(whole_usable == 0 || unreadable) << "exit 1 with a whole sequence\n" << output;
    return;
  }
  if (code != 0 && code != 3) return;
  ASSERT_TRUE(written) << output;
  proto::CalibrationResult out;
  ASSERT_TRUE(ReadTextProto(root + "/calibration.txtpb", &out).ok());
  EXPECT_TRUE(AllFinite(out)) << output;
  EXPECT_EQ(out.verdict() == proto::CalibrationResult::SUSPECT, code == 3) << output;
  ASSERT_EQ(out.sequences_size(), static_cast<int>(sequences.size()));
  std::vector<int> used_groups;
  int used = 0;
  for (int i = 0; i < out.sequences_size(); ++i) {
    if (!out.sequences(i).used()) continue;
    ++used;
    EXPECT_EQ(sequences[i].kind, Kind::kGood)
        << sequences[i].name << " used although " << sequences[i].mutation << "\n"
        << output;
    used_groups.push_back(sequences[i].group);
  }
  EXPECT_GE(used, 1) << output;
  if (code == 0) {
    EXPECT_TRUE(out.verdict() == proto::CalibrationResult::OK ||
                out.verdict() == proto::CalibrationResult::WEAK)
        << output;
    // Never OK with used sequences that disagree.
    EXPECT_TRUE(std::all_of(used_groups.begin(), used_groups.end(),
                            [&](int g) { return g == used_groups.front(); }))
        << "exit 0 fusing sequences of two groups\n"
        << output;
  }
  *dataset_out = root + "/calibration.txtpb";
}

void CheckGravityReference(const std::vector<GeneratedSequence>& sequences,
                           const std::string& root) {
  const std::string out_path = root + "/gravity_reference.txtpb";
  std::string command = testing::ToolPath("tiltcal_gravity_reference") + " --out=" + out_path;
  for (const GeneratedSequence& s : sequences) command += " " + s.dir + "/calibration.txtpb";
  std::string output;
  const int code = Run(command, {0, 1}, &output);
  if (code != 0) {
    EXPECT_FALSE(testing::FileExists(out_path)) << output;
    return;
  }
  proto::GravityReference ref;
  ASSERT_TRUE(ReadTextProto(out_path, &ref).ok()) << output;
  const Eigen::Vector3d g_f = ToEigen(ref.gravity_flat_in_imu());
  EXPECT_TRUE(g_f.allFinite()) << output;
  EXPECT_GE(g_f.norm(), kMinGravityNorm) << output;
  EXPECT_LE(g_f.norm(), kMaxGravityNorm) << output;
  for (const proto::FlatCalibrationGravity& entry : ref.flat_calibrations()) {
    if (!entry.used()) continue;
    const Eigen::Vector3d g = ToEigen(entry.gravity_in_imu());
    EXPECT_TRUE(g.allFinite()) << output;
    EXPECT_GE(g.norm(), kMinGravityNorm) << output;
    EXPECT_LE(g.norm(), kMaxGravityNorm) << output;
    const double angle_deg = geometry::AngleBetweenDeg(g, g_f);
    EXPECT_LE(angle_deg, kMaxGravityAngleDeg + 1e-9) << output;
  }
  EXPECT_FALSE(HasNonFiniteWord(output)) << output;
}

void CheckReport(const std::vector<GeneratedSequence>& sequences, const std::string& root,
                 const std::string& dataset_calibration) {
  const std::string out_path = root + "/repeatability.txt";
  std::string command = testing::ToolPath("tiltcal_report") + " --out=" + out_path;
  if (!dataset_calibration.empty()) command += " --dataset_calibration=" + dataset_calibration;
  for (const GeneratedSequence& s : sequences) command += " " + s.dir;
  std::string output;
  const int code = Run(command, {0, 1}, &output);
  if (code != 0) {
    EXPECT_FALSE(testing::FileExists(out_path)) << output;
    return;
  }
  std::vector<std::string> calibrations = {dataset_calibration};
  for (const GeneratedSequence& s : sequences) calibrations.push_back(s.dir + "/calibration.txtpb");
  EXPECT_FALSE(HasNonFiniteWord(WithoutReasons(ReadText(out_path), calibrations)))
      << ReadText(out_path);
  EXPECT_FALSE(HasNonFiniteWord(WithoutReasons(output, calibrations))) << output;
}

void CheckExport(const std::string& calibration, Generator* generator) {
  static const char* kFormats[] = {"fast_lio", "lio_sam", "urdf",   "tf_ros1",
                                   "tf_ros2",  "kalibr",  "matrix", "json"};
  const std::string format = kFormats[generator->Pick(8)];
  std::string output;
  const int code = Run(
      testing::ToolPath("tiltcal_export") + " --format=" + format + " --calibration=" + calibration,
      {0, 1, 2}, &output);
  if (code != 0) return;
  EXPECT_FALSE(HasNonFiniteWord(WithoutReasons(output, {calibration})))
      << format << " of " << calibration << "\n"
      << output;
  proto::CalibrationResult input;
  if (ReadTextProto(calibration, &input).ok()) {
    EXPECT_NE(input.verdict(), proto::CalibrationResult::SUSPECT)
        << "exported a SUSPECT calibration without --allow_suspect: " << calibration;
  }
}

TEST(CalibrationFilesProperty, HostileFilesNeverGiveAnOkOrNonFiniteResult) {
  for (const char* tool : {"tiltcal_dataset_calibration", "tiltcal_gravity_reference",
                           "tiltcal_report", "tiltcal_export"}) {
    ASSERT_TRUE(testing::FileExists(testing::ToolPath(tool))) << "build " << tool << " first";
  }
  for (unsigned seed = 1; seed <= kCases; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    testing::TempDir dir;
    Generator generator(seed);
    const std::vector<GeneratedSequence> sequences = generator.Dataset(dir.path());
    for (const GeneratedSequence& s : sequences) {
      std::filesystem::create_directories(s.dir);
      ASSERT_TRUE(WriteFileAtomically(s.dir + "/calibration.txtpb", s.text).ok());
    }
    std::string dataset_calibration;
    CheckDatasetCalibration(sequences, dir.path(), &dataset_calibration);
    CheckGravityReference(sequences, dir.path());
    CheckReport(sequences, dir.path(), dataset_calibration);
    for (const GeneratedSequence& s : sequences) {
      CheckExport(s.dir + "/calibration.txtpb", &generator);
    }
    if (!dataset_calibration.empty()) CheckExport(dataset_calibration, &generator);
    if (::testing::Test::HasFailure()) {
      std::string what;
      for (const GeneratedSequence& s : sequences) {
        what += s.name + (s.kind == Kind::kGood ? " whole" : " " + s.mutation) + " group " +
                std::to_string(s.group) + "; ";
      }
      ADD_FAILURE() << "seed " << seed << ": " << what;
      return;
    }
  }
  for (const auto& [program, counts] : ExitCounts()) {
    std::cout << program << " exits:";
    for (const auto& [code, count] : counts) std::cout << " " << code << " x" << count;
    std::cout << "\n";
  }
}

}  // namespace
}  // namespace tiltcal
