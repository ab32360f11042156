#pragma once
// Finite-difference checks shared by the energies' tests: central
// differences of a scalar function and of a gradient, a relative error, and
// random inputs from the counter-based RNG.
#include <Eigen/Core>
#include <functional>

#include "crumple/core/rng.hpp"
#include "crumple/core/types.hpp"

namespace crumple::testing {

// norm(analytic - fd) / max(norm(fd), floor)
template <typename A, typename B>
inline double relativeError(const A& analytic, const B& fd, double floor) {
  return (analytic - fd).norm() / std::max(fd.norm(), floor);
}

struct Random {
  CounterRng rng;
  std::uint64_t next = 0;
  explicit Random(std::uint64_t seed) : rng(seed, 0, RngPurpose::Generic) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * rng.uniform(next++); }
  Vec3 vec3(double scale) {
    const double a = uniform(-1, 1), b = uniform(-1, 1), c = uniform(-1, 1);
    return scale * Vec3(a, b, c);
  }
  Mat3 rotation() {
    const double a = uniform(-1, 1), b = uniform(-1, 1), c = uniform(-1, 1), d = uniform(-1, 1);
    return Quat(a, b, c, d).normalized().toRotationMatrix();
  }
};

// Central differences of a scalar function of N coordinates.
template <int N>
Eigen::Matrix<double, N, 1> fdGradient(
    const std::function<double(const Eigen::Matrix<double, N, 1>&)>& f,
    const Eigen::Matrix<double, N, 1>& x, double eps) {
  Eigen::Matrix<double, N, 1> g;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> xp = x, xm = x;
    xp[i] += eps;
    xm[i] -= eps;
    g[i] = (f(xp) - f(xm)) / (2.0 * eps);
  }
  return g;
}

// Central differences of a gradient (columns of the Hessian).
template <int N>
Eigen::Matrix<double, N, N> fdHessian(
    const std::function<Eigen::Matrix<double, N, 1>(const Eigen::Matrix<double, N, 1>&)>& g,
    const Eigen::Matrix<double, N, 1>& x, double eps) {
  Eigen::Matrix<double, N, N> h;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> xp = x, xm = x;
    xp[i] += eps;
    xm[i] -= eps;
    h.col(i) = (g(xp) - g(xm)) / (2.0 * eps);
  }
  return h;
}

}  // namespace crumple::testing
