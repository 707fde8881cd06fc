#include "bag/ros1/format.h"

namespace tiltcal::ros1 {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the ROS1 bag code assumes a little-endian host");

const char* OpName(uint8_t op) {
  switch (static_cast<Op>(op)) {
    case Op::kMessageDefinition: return "message definition";
    case Op::kMessageData: return "message data";
    case Op::kBagHeader: return "bag header";
    case Op::kIndexData: return "index data";
    case Op::kChunk: return "chunk";
    case Op::kChunkInfo: return "chunk info";
    case Op::kConnection: return "connection";
  }
  return "unknown";
}

bool NsToRosTime(int64_t ns, RosTime* t) {
  if (ns < 0) return false;
  const int64_t sec = ns / 1000000000;
  if (sec > static_cast<int64_t>(UINT32_MAX)) return false;
  t->sec = static_cast<uint32_t>(sec);
  t->nsec = static_cast<uint32_t>(ns % 1000000000);
  return true;
}

Status RecordHeader::Parse(const void* data, size_t size) {
  fields_.clear();
  const char* p = static_cast<const char*>(data);
  size_t pos = 0;
  while (pos < size) {
    if (size - pos < 4) {
      return Status::Error("record header: field length at header byte " + std::to_string(pos) +
                           " runs past the header (" + std::to_string(size) + " bytes)");
    }
    const uint32_t len = LoadU32Le(p + pos);
    if (len > size - pos - 4) {
      return Status::Error("record header: field at header byte " + std::to_string(pos) +
                           " has length " + std::to_string(len) + " past the header (" +
                           std::to_string(size) + " bytes)");
    }
    const std::string_view field(p + pos + 4, len);
    const size_t eq = field.find('=');
    if (eq == std::string_view::npos) {
      return Status::Error("record header: field at header byte " + std::to_string(pos) +
                           " has no '='");
    }
    fields_.emplace_back(field.substr(0, eq), field.substr(eq + 1));
    pos += 4 + static_cast<size_t>(len);
  }
  return Status::Ok();
}

const std::string_view* RecordHeader::Find(std::string_view name) const {
  for (auto it = fields_.rbegin(); it != fields_.rend(); ++it) {
    if (it->first == name) return &it->second;
  }
  return nullptr;
}

namespace {

Status GetFixed(const RecordHeader& header, std::string_view name, size_t size,
                const std::string_view** value) {
  *value = header.Find(name);
  if (*value == nullptr) {
    return Status::Error("record header has no field '" + std::string(name) + "'");
  }
  if ((*value)->size() != size) {
    return Status::Error("record header field '" + std::string(name) + "' has " +
                         std::to_string((*value)->size()) + " bytes, expected " +
                         std::to_string(size));
  }
  return Status::Ok();
}

}  // namespace

Status RecordHeader::GetOp(uint8_t* op) const {
  const std::string_view* value = nullptr;
  TILTCAL_RETURN_IF_ERROR(GetFixed(*this, "op", 1, &value));
  *op = static_cast<uint8_t>((*value)[0]);
  return Status::Ok();
}

Status RecordHeader::GetU32(std::string_view name, uint32_t* out) const {
  const std::string_view* value = nullptr;
  TILTCAL_RETURN_IF_ERROR(GetFixed(*this, name, 4, &value));
  *out = LoadU32Le(value->data());
  return Status::Ok();
}

Status RecordHeader::GetU64(std::string_view name, uint64_t* out) const {
  const std::string_view* value = nullptr;
  TILTCAL_RETURN_IF_ERROR(GetFixed(*this, name, 8, &value));
  *out = LoadU64Le(value->data());
  return Status::Ok();
}

Status RecordHeader::GetTime(std::string_view name, RosTime* out) const {
  const std::string_view* value = nullptr;
  TILTCAL_RETURN_IF_ERROR(GetFixed(*this, name, 8, &value));
  *out = LoadRosTime(value->data());
  return Status::Ok();
}

Status RecordHeader::GetString(std::string_view name, std::string* out) const {
  const std::string_view* value = Find(name);
  if (value == nullptr) {
    return Status::Error("record header has no field '" + std::string(name) + "'");
  }
  out->assign(value->data(), value->size());
  return Status::Ok();
}

Status ParseBufferRecord(const uint8_t* buffer, size_t size, size_t offset, BufferRecord* r) {
  if (offset > size || size - offset < 4) {
    return Status::Error("record header length at chunk offset " + std::to_string(offset) +
                         " runs past the chunk end " + std::to_string(size));
  }
  const uint32_t header_len = LoadU32Le(buffer + offset);
  if (header_len > size - offset - 4 || size - offset - 4 - header_len < 4) {
    return Status::Error("record header at chunk offset " + std::to_string(offset) +
                         " (length " + std::to_string(header_len) +
                         ") runs past the chunk end " + std::to_string(size));
  }
  const size_t data_pos = offset + 4 + header_len + 4;
  r->data_len = LoadU32Le(buffer + data_pos - 4);
  if (r->data_len > size - data_pos) {
    return Status::Error("record data at chunk offset " + std::to_string(offset) + " (length " +
                         std::to_string(r->data_len) + ") runs past the chunk end " +
                         std::to_string(size));
  }
  r->data = buffer + data_pos;
  r->end = data_pos + r->data_len;
  Status status = r->header.Parse(buffer + offset + 4, header_len);
  if (status.ok()) status = r->header.GetOp(&r->op);
  if (!status.ok()) {
    return Status::Error("record at chunk offset " + std::to_string(offset) + ": " +
                         status.message());
  }
  return Status::Ok();
}

std::string OpValue(Op op) { return std::string(1, static_cast<char>(op)); }

std::string U32Value(uint32_t value) {
  std::string out;
  AppendU32Le(&out, value);
  return out;
}

std::string U64Value(uint64_t value) {
  std::string out;
  AppendU64Le(&out, value);
  return out;
}

std::string TimeValue(RosTime t) {
  std::string out;
  AppendRosTime(&out, t);
  return out;
}

std::string BuildHeader(const HeaderFields& fields) {
  std::string out;
  for (const auto& [name, value] : fields) {
    AppendU32Le(&out, static_cast<uint32_t>(name.size() + 1 + value.size()));
    out += name;
    out += '=';
    out += value;
  }
  return out;
}

void AppendRecord(std::string* out, const HeaderFields& fields, std::string_view data) {
  const std::string header = BuildHeader(fields);
  AppendU32Le(out, static_cast<uint32_t>(header.size()));
  out->append(header);
  AppendU32Le(out, static_cast<uint32_t>(data.size()));
  out->append(data.data(), data.size());
}

}  // namespace tiltcal::ros1
