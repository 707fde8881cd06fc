#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_POINT_PRIORITY_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_POINT_PRIORITY_H_

// A fixed pseudo-random priority of point j of scan k, for choosing a
// subsample that does not change when a few candidates come or go
// (AssociationParams.selection FIXED_PRIORITY): the SplitMix64 finaliser of
// (k << 32) + j, so equal inputs give equal priorities on every run and
// platform, and the priorities of different points look independent.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tiltcal::calibrate {

inline uint64_t PointPriority(size_t scan_index, size_t point_index) {
  uint64_t z = (static_cast<uint64_t>(scan_index) << 32) + static_cast<uint64_t>(point_index) +
               0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Keeps the `keep` elements of *v of lowest priority(element), in no
// particular order.
template <typename T, typename PriorityOf>
void KeepLowestPriority(size_t keep, const PriorityOf& priority_of, std::vector<T>* v) {
  if (v->size() <= keep) return;
  std::nth_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(keep) - 1, v->end(),
                   [&](const T& a, const T& b) { return priority_of(a) < priority_of(b); });
  v->resize(keep);
}

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_POINT_PRIORITY_H_
