#ifndef TILTCAL_COMMON_CHECKED_CONVERSION_H_
#define TILTCAL_COMMON_CHECKED_CONVERSION_H_

// Conversions and integer arithmetic that report, instead of invoking
// undefined behaviour, when the result does not fit: a float → integer cast
// of NaN, ±Inf or a value outside the integer's range, and int64 sums and
// differences that overflow (extreme stamps in nanoseconds).

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

namespace tiltcal {

// x truncated toward zero as Int, or nullopt when x is NaN, infinite or
// outside [min(Int), max(Int)].
template <typename Int>
std::optional<Int> CheckedTruncate(double x) {
  static_assert(std::is_integral_v<Int>);
  if (!std::isfinite(x)) return std::nullopt;
  const double t = std::trunc(x);
  // 2^digits is exactly representable; max(Int) itself may not be.
  constexpr double kUpper =
      2.0 * static_cast<double>(Int{1} << (std::numeric_limits<Int>::digits - 1));
  constexpr double kLower = std::is_signed_v<Int> ? -kUpper : 0.0;
  if (t >= kUpper || t < kLower) return std::nullopt;
  return static_cast<Int>(t);
}

// x rounded to the nearest integer (halves away from zero) as Int, or
// nullopt like CheckedTruncate.
template <typename Int>
std::optional<Int> CheckedRound(double x) {
  if (!std::isfinite(x)) return std::nullopt;
  return CheckedTruncate<Int>(std::round(x));
}

// ceil(x) as Int, or nullopt like CheckedTruncate.
template <typename Int>
std::optional<Int> CheckedCeil(double x) {
  if (!std::isfinite(x)) return std::nullopt;
  return CheckedTruncate<Int>(std::ceil(x));
}

// Seconds → nanoseconds, rounded; nullopt when the result is not an int64.
inline std::optional<int64_t> SecondsToNs(double seconds) {
  return CheckedRound<int64_t>(seconds * 1e9);
}

// a + b and a − b, or nullopt on int64 overflow.
inline std::optional<int64_t> CheckedAdd(int64_t a, int64_t b) {
  int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) return std::nullopt;
  return sum;
}
inline std::optional<int64_t> CheckedSub(int64_t a, int64_t b) {
  int64_t difference = 0;
  if (__builtin_sub_overflow(a, b, &difference)) return std::nullopt;
  return difference;
}

// a − b in seconds as a double, exact for |a − b| < 2^53 ns and without
// overflow for any two int64 stamps (the difference is taken in
// long double when it does not fit an int64).
inline double DifferenceSeconds(int64_t a, int64_t b) {
  if (const std::optional<int64_t> d = CheckedSub(a, b)) return static_cast<double>(*d) * 1e-9;
  return static_cast<double>(static_cast<long double>(a) - static_cast<long double>(b)) * 1e-9;
}

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_CHECKED_CONVERSION_H_
