// libFuzzer harness: any bytes as a record stream, plain or LZ4-framed
// (common/io/record_stream.h): the header, then every record as a Scan until
// the end or the first error.
#include <cstddef>
#include <cstdint>

#include "common/io/record_stream.h"
#include "fuzz/fuzz_input_file.h"
#include "tiltcal/proto/scan.pb.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tiltcal::fuzz::FuzzInputFile file(data, size);
  if (!file.ok()) return 0;
  tiltcal::RecordReader reader;
  if (!reader.Open(file.path()).ok()) return 0;
  tiltcal::proto::Scan scan;
  for (;;) {
    bool end = false;
    if (!reader.Read(&scan, &end).ok() || end) break;
  }
  return 0;
}
