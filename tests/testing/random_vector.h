#ifndef TILTCAL_TESTS_TESTING_RANDOM_VECTOR_H_
#define TILTCAL_TESTS_TESTING_RANDOM_VECTOR_H_

// Three draws of one distribution as a vector, in a fixed order.
// Eigen::Vector3d(d(rng), d(rng), d(rng)) leaves the order of the draws to
// the compiler (gcc evaluates the arguments right to left, clang left to
// right), so the same seed gave different data under each. The draws here
// go z, y, x: the order gcc used when the tests' expected values were
// computed. Tests that mix distributions in one vector draw into named
// variables in the same order.

#include <Eigen/Core>

namespace tiltcal::testing {

template <typename Distribution, typename Rng>
Eigen::Vector3d RandomVector3(Distribution& dist, Rng& rng) {
  const double z = dist(rng);
  const double y = dist(rng);
  const double x = dist(rng);
  return Eigen::Vector3d(x, y, z);
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_RANDOM_VECTOR_H_
