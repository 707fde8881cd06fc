// The precompiled header of the library and stage targets (TILTCAL_PCH,
// cmake/tiltcal_helpers.cmake): standard library, Eigen, fmt and protobuf
// headers that most translation units include, parsed once per build instead
// of once per file. Every file still includes what it uses; a build with
// -DTILTCAL_PCH=OFF checks that.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <fmt/format.h>
#include <google/protobuf/generated_message_reflection.h>
#include <google/protobuf/message.h>
#include <google/protobuf/repeated_field.h>
