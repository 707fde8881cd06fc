#include "tests/stages/calibrate/short_sequence_fixture.h"

namespace tiltcal::calibrate {

std::unique_ptr<testing::TempDir> ShortSequenceTest::dir_;
std::string ShortSequenceTest::setup_error_;
proto::SimulationTruth ShortSequenceTest::truth_;

}  // namespace tiltcal::calibrate
