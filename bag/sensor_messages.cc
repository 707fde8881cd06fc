#include "bag/sensor_messages.h"

namespace tiltcal::bag {

size_t PointFieldTypeSize(uint8_t datatype) {
  switch (datatype) {
    case kInt8:
    case kUint8: return 1;
    case kInt16:
    case kUint16: return 2;
    case kInt32:
    case kUint32:
    case kFloat32: return 4;
    case kFloat64: return 8;
    default: return 0;
  }
}

std::string PointFieldTypeName(uint8_t datatype) {
  switch (datatype) {
    case kInt8: return "INT8";
    case kUint8: return "UINT8";
    case kInt16: return "INT16";
    case kUint16: return "UINT16";
    case kInt32: return "INT32";
    case kUint32: return "UINT32";
    case kFloat32: return "FLOAT32";
    case kFloat64: return "FLOAT64";
    default: return "type " + std::to_string(datatype);
  }
}

}  // namespace tiltcal::bag
