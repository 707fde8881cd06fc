#include "common/io/provenance.h"

#include <sys/stat.h>

#include <ctime>

#include <google/protobuf/text_format.h>

#include "tiltcal/version.h"

namespace tiltcal {

proto::Provenance MakeProvenance(const std::string& producer,
                                 const google::protobuf::Message& params,
                                 const std::vector<InputPath>& inputs,
                                 const std::string& command_line) {
  proto::Provenance provenance;
  provenance.set_producer(producer);
  provenance.set_producer_version(kVersion);
  google::protobuf::TextFormat::PrintToString(params, provenance.mutable_params_txtpb());
  for (const auto& [role, path] : inputs) {
    proto::InputFile* input = provenance.add_inputs();
    input->set_role(role);
    input->set_path(path);
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0) input->set_size_bytes(info.st_size);
  }
  const std::time_t now = std::time(nullptr);
  char buffer[32];
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &utc);
  provenance.set_created_utc(buffer);
  provenance.set_command_line(command_line);
  return provenance;
}

std::string JoinCommandLine(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) line += ' ';
    line += argv[i];
  }
  return line;
}

}  // namespace tiltcal
