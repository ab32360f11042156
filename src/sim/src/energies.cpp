#include "crumple/sim/energies.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace crumple::sim {
namespace {

// Cross-product matrix: skew(a) * b == a.cross(b).
Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return s;
}

// Nearest PSD matrix to m on the span of q's orthonormal columns, m being
// zero outside it: m = Q (Q^T m Q) Q^T with negative eigenvalues of the
// middle factor clamped. Returns true when m changed.
template <int N, int R>
bool projectOnBasis(Eigen::Matrix<double, N, N>& m, const Eigen::Matrix<double, N, R>& q) {
  Eigen::Matrix<double, R, R> reduced = q.transpose() * m * q;
  reduced = (0.5 * (reduced + reduced.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, R, R>> eig(reduced);
  if (eig.info() != Eigen::Success) {
    m.setConstant(std::numeric_limits<double>::quiet_NaN());  // caught by the finiteness checks
    return true;
  }
  Eigen::Matrix<double, R, 1> lambda = eig.eigenvalues();
  if (lambda.minCoeff() >= 0.0) return false;
  lambda = lambda.cwiseMax(0.0);
  const Eigen::Matrix<double, N, R> qv = q * eig.eigenvectors();
  m = qv * lambda.asDiagonal() * qv.transpose();
  return true;
}

template <int N>
bool projectToPsdImpl(Eigen::Matrix<double, N, N>& m) {
  return projectOnBasis<N, N>(m, Eigen::Matrix<double, N, N>::Identity());
}

// An orthonormal basis of the vectors of R^V (V vertices, one coordinate)
// orthogonal to (1, ..., 1): Helmert's contrasts, column k = (1, ..., 1, -k,
// 0, ...) / sqrt(k (k + 1)) with k ones.
template <int V>
Eigen::Matrix<double, V, V - 1> helmertBasis() {
  Eigen::Matrix<double, V, V - 1> q = Eigen::Matrix<double, V, V - 1>::Zero();
  for (int k = 1; k < V; ++k) {
    const double s = 1.0 / std::sqrt(static_cast<double>(k * (k + 1)));
    for (int i = 0; i < k; ++i) q(i, k - 1) = s;
    q(k, k - 1) = -k * s;
  }
  return q;
}

// H = Q (Q^T H Q) Q^T for H annihilating translations, Q = helmert (x) I3.
template <int V>
bool projectTranslationInvariantImpl(Eigen::Matrix<double, 3 * V, 3 * V>& m) {
  constexpr int N = 3 * V, R = 3 * (V - 1);
  static const Eigen::Matrix<double, N, R> q = [] {
    const Eigen::Matrix<double, V, V - 1> h = helmertBasis<V>();
    Eigen::Matrix<double, N, R> full = Eigen::Matrix<double, N, R>::Zero();
    for (int i = 0; i < V; ++i)
      for (int k = 0; k < V - 1; ++k)
        full.template block<3, 3>(3 * i, 3 * k) = h(i, k) * Mat3::Identity();
    return full;
  }();
  return projectOnBasis<N, R>(m, q);
}

}  // namespace

MembraneModuli membraneModuli(const Material& material) {
  const double e = material.youngsModulus;
  const double nu = material.poissonRatio;
  MembraneModuli m;
  m.lambda = e * nu / (1.0 - nu * nu);  // plane stress
  m.mu = e / (2.0 * (1.0 + nu));
  m.thickness = material.thickness;
  return m;
}

TriangleRest triangleRest(const Vec2& p0, const Vec2& p1, const Vec2& p2) {
  Mat2 dm;
  dm.col(0) = p1 - p0;
  dm.col(1) = p2 - p0;
  const double det = dm.determinant();
  if (!(std::abs(det) > 0.0) || !std::isfinite(det))
    throw std::invalid_argument("degenerate pattern triangle");
  TriangleRest r;
  r.dmInverse = dm.inverse();
  r.area = 0.5 * std::abs(det);
  return r;
}

Mat2 greenStrain(const Vec3& x0, const Vec3& x1, const Vec3& x2, const TriangleRest& rest) {
  Eigen::Matrix<double, 3, 2> ds;
  ds.col(0) = x1 - x0;
  ds.col(1) = x2 - x0;
  const Eigen::Matrix<double, 3, 2> f = ds * rest.dmInverse;
  return 0.5 * (f.transpose() * f - Mat2::Identity());
}

double maxAbsPrincipal(const Mat2& s) {
  const double mean = 0.5 * (s(0, 0) + s(1, 1));
  const double half = 0.5 * (s(0, 0) - s(1, 1));
  const double off = 0.5 * (s(0, 1) + s(1, 0));
  return std::abs(mean) + std::sqrt(half * half + off * off);
}

double membraneEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const TriangleRest& rest,
                      const MembraneModuli& moduli, Vec9* gradient, Mat9* hessian) {
  // F = sum_a x_a g_a^T with g_1, g_2 the rows of Dm^-1 and g_0 = -(g_1 + g_2).
  const Vec2 g[3] = {-(rest.dmInverse.row(0) + rest.dmInverse.row(1)).transpose(),
                     rest.dmInverse.row(0).transpose(), rest.dmInverse.row(1).transpose()};
  Eigen::Matrix<double, 3, 2> ds;
  ds.col(0) = x1 - x0;
  ds.col(1) = x2 - x0;
  const Eigen::Matrix<double, 3, 2> f = ds * rest.dmInverse;
  const Mat2 e = 0.5 * (f.transpose() * f - Mat2::Identity());
  const double tr = e.trace();
  const double vol = rest.area * moduli.thickness;
  const double energy = vol * (0.5 * moduli.lambda * tr * tr + moduli.mu * e.squaredNorm());
  if (gradient == nullptr && hessian == nullptr) return energy;

  // Second Piola-Kirchhoff stress S = lambda tr(E) I + 2 mu E; first Piola P = F S.
  const Mat2 s = moduli.lambda * tr * Mat2::Identity() + 2.0 * moduli.mu * e;
  if (gradient != nullptr) {
    const Eigen::Matrix<double, 3, 2> p = f * s;
    for (int a = 0; a < 3; ++a) gradient->segment<3>(3 * a) = vol * (p * g[a]);
  }
  if (hessian != nullptr) {
    // d^2W/dx_a dx_b = vol [ (g_a.S g_b) I + lambda (F g_a)(F g_b)^T
    //                        + mu (F g_b)(F g_a)^T + mu (g_a.g_b) F F^T ]
    const Mat3 ff = f * f.transpose();
    Vec3 fg[3];
    for (int a = 0; a < 3; ++a) fg[a] = f * g[a];
    for (int a = 0; a < 3; ++a) {
      for (int b = a; b < 3; ++b) {
        const Mat3 block =
            vol *
            (g[a].dot(s * g[b]) * Mat3::Identity() + moduli.lambda * fg[a] * fg[b].transpose() +
             moduli.mu * fg[b] * fg[a].transpose() + moduli.mu * g[a].dot(g[b]) * ff);
        hessian->block<3, 3>(3 * a, 3 * b) = block;
        if (b != a) hessian->block<3, 3>(3 * b, 3 * a) = block.transpose();
      }
    }
  }
  return energy;
}

double dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                     Vec12* gradient, Mat12* hessian) {
  // Relative coordinates: e = x1 - x0 (the hinge), a = x2 - x0, b = x3 - x0.
  // n_A = e x a, n_B = b x e; then (Lagrange / Binet-Cauchy identities)
  //   c = n_A . n_B = (e.a)(e.b) - (e.e)(a.b)
  //   y = (n_A x n_B) . e/|e| = |e| s,  s = e . (b x a)
  // and theta = atan2(y, c). Derivatives are taken in (e, a, b), then mapped
  // to (x0, x1, x2, x3) by the constant linear map.
  const Vec3 e = x1 - x0;
  const Vec3 a = x2 - x0;
  const Vec3 b = x3 - x0;
  const double ee = e.dot(e), ea = e.dot(a), eb = e.dot(b), ab = a.dot(b);
  const double len = std::sqrt(ee);
  const Vec3 bxa = b.cross(a);
  const double s = e.dot(bxa);
  const double y = len * s;
  const double c = ea * eb - ee * ab;
  const double theta = std::atan2(y, c);
  if (gradient == nullptr && hessian == nullptr) return theta;

  const Vec3 exb = e.cross(b);
  const Vec3 axe = a.cross(e);
  const Vec3 ehat = e / len;
  Vec9 gs, gy, gc;
  gs << bxa, exb, axe;
  gy << s * ehat + len * bxa, len * exb, len * axe;
  gc << eb * a + ea * b - 2.0 * ab * e, eb * e - ee * b, ea * e - ee * a;

  const double r2 = y * y + c * c;
  const Vec9 gTheta = (c * gy - y * gc) / r2;
  if (gradient != nullptr) {
    gradient->segment<3>(3) = gTheta.segment<3>(0);
    gradient->segment<3>(6) = gTheta.segment<3>(3);
    gradient->segment<3>(9) = gTheta.segment<3>(6);
    gradient->segment<3>(0) = -(gTheta.segment<3>(0) + gTheta.segment<3>(3) + gTheta.segment<3>(6));
  }
  if (hessian == nullptr) return theta;

  // Hessian of s (trilinear): blocks ea = [b]x, eb = -[a]x, ab = [e]x.
  Mat9 hs = Mat9::Zero();
  hs.block<3, 3>(0, 3) = skew(b);
  hs.block<3, 3>(0, 6) = -skew(a);
  hs.block<3, 3>(3, 6) = skew(e);
  hs.block<3, 3>(3, 0) = hs.block<3, 3>(0, 3).transpose();
  hs.block<3, 3>(6, 0) = hs.block<3, 3>(0, 6).transpose();
  hs.block<3, 3>(6, 3) = hs.block<3, 3>(3, 6).transpose();
  // y = |e| s:  H_y = |e| H_s + u gs^T + gs u^T + s H_|e|,  u = d|e| = (ehat, 0, 0).
  Mat9 hy = len * hs;
  hy.block<3, 9>(0, 0) += ehat * gs.transpose();
  hy.block<9, 3>(0, 0) += gs * ehat.transpose();
  hy.block<3, 3>(0, 0) += (s / len) * (Mat3::Identity() - ehat * ehat.transpose());
  // c = (e.a)(e.b) - (e.e)(a.b)
  Mat9 hc = Mat9::Zero();
  hc.block<3, 3>(0, 0) = a * b.transpose() + b * a.transpose() - 2.0 * ab * Mat3::Identity();
  hc.block<3, 3>(0, 3) = eb * Mat3::Identity() + b * e.transpose() - 2.0 * e * b.transpose();
  hc.block<3, 3>(0, 6) = ea * Mat3::Identity() + a * e.transpose() - 2.0 * e * a.transpose();
  hc.block<3, 3>(3, 6) = e * e.transpose() - ee * Mat3::Identity();
  hc.block<3, 3>(3, 0) = hc.block<3, 3>(0, 3).transpose();
  hc.block<3, 3>(6, 0) = hc.block<3, 3>(0, 6).transpose();
  hc.block<3, 3>(6, 3) = hc.block<3, 3>(3, 6).transpose();
  // theta = atan2(y, c):
  //   H = (c H_y - y H_c + gc gy^T - gy gc^T) / r2 - 2 g (y gy + c gc)^T / r2
  Mat9 h9 = (c * hy - y * hc + gc * gy.transpose() - gy * gc.transpose() -
             2.0 * gTheta * (y * gy + c * gc).transpose()) /
            r2;
  h9 = (0.5 * (h9 + h9.transpose())).eval();

  // Map (e, a, b) -> (x0, x1, x2, x3): x1, x2, x3 blocks are the (e, a, b)
  // blocks; x0 gets minus the sums.
  Mat12& h = *hessian;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) h.block<3, 3>(3 + 3 * i, 3 + 3 * j) = h9.block<3, 3>(3 * i, 3 * j);
  for (int j = 0; j < 3; ++j) {
    const Mat3 colSum =
        h9.block<3, 3>(0, 3 * j) + h9.block<3, 3>(3, 3 * j) + h9.block<3, 3>(6, 3 * j);
    h.block<3, 3>(0, 3 + 3 * j) = -colSum;
    h.block<3, 3>(3 + 3 * j, 0) = -colSum.transpose();
  }
  h.block<3, 3>(0, 0) = -(h.block<3, 3>(0, 3) + h.block<3, 3>(0, 6) + h.block<3, 3>(0, 9));
  return theta;
}

double hingeStiffness(double bendingStiffness, double factor, double restEdgeLengthSquared,
                      double restArea0, double restArea1) {
  // k_b * 3 |e|^2 / (A1 + A2) with k_b = D / 6 (calibration in the header).
  return 0.5 * bendingStiffness * factor * restEdgeLengthSquared / (restArea0 + restArea1);
}

double bendingEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                     double stiffness, double restAngle, Vec12* gradient, Mat12* hessian) {
  if (gradient == nullptr && hessian == nullptr) {
    const double d = dihedralAngle(x0, x1, x2, x3) - restAngle;
    return stiffness * d * d;
  }
  Vec12 g;
  const double theta = dihedralAngle(x0, x1, x2, x3, &g, hessian);
  const double d = theta - restAngle;
  if (hessian != nullptr) {
    // d^2/dx^2 k d^2 = 2k (g g^T + d H_theta)
    *hessian *= 2.0 * stiffness * d;
    hessian->noalias() += (2.0 * stiffness) * g * g.transpose();
  }
  if (gradient != nullptr) *gradient = 2.0 * stiffness * d * g;
  return stiffness * d * d;
}

double gripEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& weights,
                  const Vec3& target, double stiffness, Vec9* gradient) {
  const Vec3 r = weights(0) * x0 + weights(1) * x1 + weights(2) * x2 - target;
  if (gradient != nullptr)
    for (int a = 0; a < 3; ++a) gradient->segment<3>(3 * a) = stiffness * weights(a) * r;
  return 0.5 * stiffness * r.squaredNorm();
}

bool projectToPsd(Mat9& m) { return projectToPsdImpl<9>(m); }
bool projectToPsd(Mat12& m) { return projectToPsdImpl<12>(m); }
bool projectTranslationInvariantToPsd(Mat9& m) { return projectTranslationInvariantImpl<3>(m); }
bool projectTranslationInvariantToPsd(Mat12& m) { return projectTranslationInvariantImpl<4>(m); }

}  // namespace crumple::sim
