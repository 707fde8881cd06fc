#ifndef TILTCAL_STAGES_CALIBRATE_PROGRESS_H_
#define TILTCAL_STAGES_CALIBRATE_PROGRESS_H_

// What tiltcal_calibrate reports as it goes: wall and CPU seconds of its
// phases (CalibrationResult.timings) and its log lines on stderr.

#include <chrono>
#include <ctime>
#include <ostream>
#include <string>

#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

using Clock = std::chrono::steady_clock;

inline double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU time of the process (all threads), s.
inline double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

inline void AddTiming(const std::string& phase, double seconds, proto::CalibrationResult* result) {
  proto::PhaseTiming* t = result->add_timings();
  t->set_phase(phase);
  t->set_seconds(seconds);
}

inline void Log(std::ostream* log, const std::string& line) {
  if (log != nullptr) *log << "tiltcal_calibrate: " << line << "\n" << std::flush;
}

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROGRESS_H_
