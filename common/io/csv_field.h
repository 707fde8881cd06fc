#ifndef TILTCAL_COMMON_IO_CSV_FIELD_H_
#define TILTCAL_COMMON_IO_CSV_FIELD_H_

#include <string>

namespace tiltcal {

// One field of a CSV row as RFC 4180 writes it: `text` as is, or in double
// quotes with each " doubled when it holds a comma, a double quote, CR or
// LF. The one rule of every CSV the project writes (repeatability.csv,
// tiltcal_inspect csv); Python's csv module reads the field back unchanged.
std::string CsvField(const std::string& text);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_CSV_FIELD_H_
