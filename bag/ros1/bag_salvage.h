#ifndef TILTCAL_BAG_ROS1_BAG_SALVAGE_H_
#define TILTCAL_BAG_ROS1_BAG_SALVAGE_H_

// The reading of a bag without index (index_pos 0 in the bag header: a
// recording that was interrupted before its index was written). The records
// are scanned one by one from the first after the bag header, and the index
// is rebuilt from the chunks: every complete message is kept, including those
// of a chunk still open (uncompressed, size never written) at the end.

#include <cstdint>
#include <string>

#include "bag/ros1/bag_index.h"
#include "bag/ros1/bag_reader.h"
#include "bag/ros1/chunk_codec.h"
#include "bag/ros1/record_file.h"
#include "common/status.h"

namespace tiltcal::ros1 {

// What the scan recovered.
struct SalvageResult {
  int64_t num_messages = 0;
  // What could not be recovered and why the scan stopped ("" when nothing
  // was lost).
  std::string note;
};

// Scans `file` from `first_record_pos` into *index (connections, chunks,
// entries sorted by (time, chunk, offset)). Chunks are decompressed with
// `decompressor` and counted in *stats. A damaged record ends the scan (with
// result->note saying where and why); errors only for I/O failures.
Status SalvageUnindexedBag(const RecordFile& file, uint64_t first_record_pos,
                           ChunkDecompressor* decompressor, ReaderStats* stats, BagIndex* index,
                           SalvageResult* result);

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_BAG_SALVAGE_H_
