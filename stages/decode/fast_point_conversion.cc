#include "stages/decode/fast_point_conversion.h"

#include <cstring>
#include <type_traits>

#include "stages/decode/point_validity.h"

namespace tiltcal::decode {
namespace {

using ros1::PointCloud2View;

struct NoField {};

template <typename T>
inline T Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// std::llround(v) for |v| < 2^52 (half away from zero): v - trunc(v) is exact.
inline int64_t RoundHalfAwayFromZero(double v) {
  const int64_t i = static_cast<int64_t>(v);
  const double fraction = v - static_cast<double>(i);
  return i + static_cast<int64_t>(fraction >= 0.5) - static_cast<int64_t>(fraction <= -0.5);
}

enum class FastTime { kNone, kVelodyneFloat32, kOusterUint32 };

template <typename IntensityT, typename RingT, FastTime kTime>
bool ConvertFast(const PointCloud2View& cloud, const uint32_t offsets[6], double min_range2,
                 const FastColumns& out, FastResult* result) {
  const uint32_t ox = offsets[0], oy = offsets[1], oz = offsets[2];
  const uint32_t oi = offsets[3], orng = offsets[4], ot = offsets[5];
  const uint64_t width = cloud.width;
  const uint32_t step = cloud.point_step;
  // Local copies: the column stores could otherwise alias `out` and `cloud`
  // and force reloads of the pointers on every point.
  float* const xs = out.x;
  float* const ys = out.y;
  float* const zs = out.z;
  float* const is = out.intensity;
  uint32_t* const rs = out.ring;
  int32_t* const ts = out.time_offset_ns;
  const uint8_t* const data = cloud.data;
  const uint64_t height = cloud.height;
  const uint64_t row_step = cloud.row_step;
  uint32_t dropped_invalid = 0;
  uint32_t dropped_range = 0;
  int k = 0;
  for (uint64_t r = 0; r < height; ++r) {
    const uint8_t* p = data + r * row_step;
    for (uint64_t c = 0; c < width; ++c, p += step) {
      const float x = Load<float>(p + ox);
      const float y = Load<float>(p + oy);
      const float z = Load<float>(p + oz);
      const PointCheck check = CheckPoint(x, y, z, min_range2);
      if (check != PointCheck::kValid) {
        ++(check == PointCheck::kInvalid ? dropped_invalid : dropped_range);
        continue;
      }
      int64_t offset_ns = 0;
      if constexpr (kTime == FastTime::kVelodyneFloat32) {
        const double v = Load<float>(p + ot);  // s relative to the stamp
        if (!IsValidRelativeSeconds(v)) {
          ++dropped_invalid;
          continue;
        }
        offset_ns = RoundHalfAwayFromZero(v * 1e9);
      } else if constexpr (kTime == FastTime::kOusterUint32) {
        offset_ns = Load<uint32_t>(p + ot);  // ns relative to the stamp, exact
      }
      if (!FitsInt32(offset_ns)) return false;
      xs[k] = x;
      ys[k] = y;
      zs[k] = z;
      if constexpr (std::is_same_v<IntensityT, NoField>) {
        is[k] = 0.0f;
      } else {
        is[k] = static_cast<float>(static_cast<double>(Load<IntensityT>(p + oi)));
      }
      if constexpr (!std::is_same_v<RingT, NoField>) {
        rs[k] = static_cast<uint32_t>(Load<RingT>(p + orng));
      }
      ts[k] = static_cast<int32_t>(offset_ns);
      ++k;
    }
  }
  result->count = k;
  result->dropped_invalid = dropped_invalid;
  result->dropped_range = dropped_range;
  return true;
}

template <typename IntensityT, typename RingT>
FastConverter PickTime(FastTime time) {
  switch (time) {
    case FastTime::kNone: return &ConvertFast<IntensityT, RingT, FastTime::kNone>;
    case FastTime::kVelodyneFloat32:
      return &ConvertFast<IntensityT, RingT, FastTime::kVelodyneFloat32>;
    case FastTime::kOusterUint32: return &ConvertFast<IntensityT, RingT, FastTime::kOusterUint32>;
  }
  return nullptr;
}

template <typename IntensityT>
FastConverter PickRing(const PointFieldAccessor& ring, FastTime time) {
  if (!ring.present) return PickTime<IntensityT, NoField>(time);
  switch (ring.type) {
    case ros1::kUint8: return PickTime<IntensityT, uint8_t>(time);
    case ros1::kUint16: return PickTime<IntensityT, uint16_t>(time);
    default: return nullptr;
  }
}

}  // namespace

FastConverter PickFastConverter(bool swap, const CloudLayout& layout) {
  if (swap || layout.x.type != ros1::kFloat32 || layout.y.type != ros1::kFloat32 ||
      layout.z.type != ros1::kFloat32) {
    return nullptr;
  }
  FastTime fast_time;
  if (layout.source == proto::POINT_TIME_NONE) {
    fast_time = FastTime::kNone;
  } else if (layout.source == proto::POINT_TIME_VELODYNE_TIME &&
             layout.time.type == ros1::kFloat32) {
    fast_time = FastTime::kVelodyneFloat32;
  } else if (layout.source == proto::POINT_TIME_OUSTER_T && layout.time.type == ros1::kUint32) {
    fast_time = FastTime::kOusterUint32;
  } else {
    return nullptr;
  }
  if (!layout.intensity.present) return PickRing<NoField>(layout.ring, fast_time);
  switch (layout.intensity.type) {
    case ros1::kFloat32: return PickRing<float>(layout.ring, fast_time);
    case ros1::kUint8: return PickRing<uint8_t>(layout.ring, fast_time);
    case ros1::kUint16: return PickRing<uint16_t>(layout.ring, fast_time);
    default: return nullptr;
  }
}

}  // namespace tiltcal::decode
