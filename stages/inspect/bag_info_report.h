#ifndef TILTCAL_STAGES_INSPECT_BAG_INFO_REPORT_H_
#define TILTCAL_STAGES_INSPECT_BAG_INFO_REPORT_H_

#include <ostream>

#include "stages/inspect/bag_info.h"

namespace tiltcal::inspect {

// `tiltcal_inspect info --bag=B`: aligned text, times as seconds since the
// epoch with their nine decimals (exact ns), one "warning: ..." line per
// warning at the end. Names from the bag are shown with their control
// characters as \xNN.
void WriteBagInfoText(const BagInfo& info, std::ostream& out);

// The same as one JSON object (keys in stages/inspect/README.md, "info
// --bag"); times in ns as integers, null where there is none.
void WriteBagInfoJson(const BagInfo& info, std::ostream& out);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_BAG_INFO_REPORT_H_
