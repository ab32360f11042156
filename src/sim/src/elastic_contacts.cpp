// ElasticSheet's contacts with colliders and with itself: penalties on
// frozen tangent planes inside the step, the failsafe after it, and the
// contact samples (friction, sound) it keeps (paper Sec. 4; docs/CONTACTS.md).
#include "crumple/sim/elastic_sheet.hpp"
#include "elastic_sheet_impl.hpp"

namespace crumple::sim {

// One backward Euler step from the current state at t0 to t1.
// On failure returns false with a reason and leaves the state untouched.
// Contacts (paper Sec. 4; docs/CONTACTS.md): a free vertex that may come within the
// contact distance D of a collider, or of another layer of the sheet, during
// the step gets that surface's tangent plane (point p, outward normal m) at
// the start of the step, frozen for the step, and the penalty
// k/2 max(0, D - m.(x - p))^2 with k = kContactScale * mass / h^2 (a stiff
// spring on the inertia's scale). A collider's plane is taken where the
// collider ends the step; a layer's where its velocity carries it (each side
// of a self-contact sees the other one frozen: a Jacobi split that keeps the
// system's sparsity, the reaction reaching the other layer through its own
// vertices' contacts). resolveContacts is the failsafe.
void ElasticSheet::Impl::findContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk,
                                      double h, StepStats& stats) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  contactPlanes.clear();
  faceContacts.clear();
  selfPairs.clear();
  const double dist = contact.distance;
  // The predictor leaves out what gravity adds over the step.
  const double fall = h * h * params.gravity.norm();
  if (collidersOn()) {
    const auto start = Clock::now();
    const ColliderSet& set = *contact.colliders;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (freeIndex[i] < 0) continue;
      const double reach = 2.0 * dist + kReachMoves * (xk[i] - xn[i]).norm() + fall;
      if (const auto c = set.nearest(xn[i], reach)) {
        const double k = kContactScale * mass[i] / (h * h);
        // The normal force the penalty exerted at x_n, lagged for friction.
        const double lambda = k * std::max(0.0, dist - c->distance);
        contactPlanes.push_back({static_cast<int>(i), c->collider, c->point, c->normal,
                                 set.surfaceDisplacement(c->collider, c->point),
                                 set.friction(c->collider), lambda, k});
      }
    }
    findFaceContacts(xn, xk, h, fall);
    stats.contactMs += since(start);
  }
  if (contact.self != SelfContactMode::Off) {
    const auto start = Clock::now();
    if (contact.self == SelfContactMode::On || sheetIsFolded(triangles, xn, contact.foldSpread)) {
      ++stats.selfContactSteps;
      // Pairs that may come within 2 D over the predicted move.
      if (!selfDetector) selfDetector.emplace(triangles, pattern, dist);
      std::vector<char> mask(vertexCount, 0);
      for (std::size_t i = 0; i < vertexCount; ++i) mask[i] = freeIndex[i] >= 0 ? 1 : 0;
      selfPairs = selfDetector->find(xn, xk, 2.0 * dist + 2.0 * fall, &mask);
      for (const SelfContactPair& p : selfPairs) {
        const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
        Vec3 at = Vec3::Zero(), motion = Vec3::Zero();
        for (std::size_t a = 0; a < 3; ++a) {
          const auto j = static_cast<std::size_t>(t[a]);
          at += p.weights[a] * xn[j];
          motion += p.weights[a] * (xk[j] - xn[j]);  // the predictor: x_n + h v_n, or the pin
        }
        const auto vi = static_cast<std::size_t>(p.vertex);
        const double k = kContactScale * mass[vi] / (h * h);
        ContactPlane plane{p.vertex,
                           -1,
                           at + motion,
                           p.normal,
                           motion,
                           contact.selfFriction,
                           k * std::max(0.0, dist - p.distance),
                           k};
        if (!p.face) {
          plane.toTriangle = true;
          for (std::size_t a = 0; a < 3; ++a)
            plane.triangle[a] = xk[static_cast<std::size_t>(t[a])];
        }
        contactPlanes.push_back(plane);
      }
    }
    stats.selfContactMs += since(start);
  }
  contactVertexSteps += static_cast<long>(contactPlanes.size() + faceContacts.size());
}

void ElasticSheet::Impl::findFaceContacts(const std::vector<Vec3>& xn, const std::vector<Vec3>& xk,
                                          double h, double fall) {
  const std::vector<ColliderProbe> probes = contact.colliders->probes();
  if (probes.empty()) return;
  const double dist = contact.distance;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const auto i0 = static_cast<std::size_t>(tri[0]), i1 = static_cast<std::size_t>(tri[1]),
               i2 = static_cast<std::size_t>(tri[2]);
    if (freeIndex[i0] < 0 && freeIndex[i1] < 0 && freeIndex[i2] < 0) continue;
    const Vec3 lo = xn[i0].cwiseMin(xn[i1]).cwiseMin(xn[i2]);
    const Vec3 hi = xn[i0].cwiseMax(xn[i1]).cwiseMax(xn[i2]);
    const double moves =
        std::max({(xk[i0] - xn[i0]).norm(), (xk[i1] - xn[i1]).norm(), (xk[i2] - xn[i2]).norm()});
    for (const ColliderProbe& p : probes) {
      const double reach = p.radius + 2.0 * dist + kReachMoves * moves + fall;
      if (((p.point - lo).array() < -reach).any() || ((p.point - hi).array() > reach).any())
        continue;
      const std::array<double, 3> w = closestBarycentricOnTriangle(p.point, xn[i0], xn[i1], xn[i2]);
      if (std::max({w[0], w[1], w[2]}) > 1.0 - 1e-9) continue;  // at a vertex: its own contact
      const Vec3 q = w[0] * xn[i0] + w[1] * xn[i1] + w[2] * xn[i2];
      const double d = (q - p.point).norm();
      if (!(d < reach)) continue;
      Vec3 n = (xn[i1] - xn[i0]).cross(xn[i2] - xn[i0]);
      if (d > 1e-9 * dist) {
        n = (q - p.point) / d;
      } else if (n.norm() > 0.0) {
        n.normalize();  // the probe is on the face: push the face along its normal
      } else {
        continue;
      }
      const double m = w[0] * mass[i0] + w[1] * mass[i1] + w[2] * mass[i2];
      faceContacts.push_back(
          {static_cast<int>(t), p.collider, w, p.point, p.radius, n, kContactScale * m / (h * h)});
    }
  }
}

// Failsafe: a free vertex the penalty left nearer than (1 - slack) D to a
// collider (a contact the frozen plane missed), or nearer than that to a
// triangle of another layer or through it, is moved out to D, and loses its
// velocity into that surface (pushed). Then the step's contact samples:
// every plane whose penalty is active at the solution, or whose vertex was
// pushed, merged per (vertex, collider).
void ElasticSheet::Impl::resolveContacts(const std::vector<Vec3>& xn, std::vector<Vec3>& xk,
                                         double h, StepStats& stats, std::vector<Pushed>& pushed) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  const double dist = contact.distance;
  const double minGap = (1.0 - kFailsafeSlack) * dist;
  // Samples from the solution the penalty reached (before any projection).
  std::vector<ContactSample> samples;
  for (const auto& cp : contactPlanes) {
    const auto vi = static_cast<std::size_t>(cp.vertex);
    const double gap = cp.gap(xk[vi], dist, nullptr);
    if (!(gap > 0.0)) continue;
    const Mat3 t = Mat3::Identity() - cp.normal * cp.normal.transpose();
    samples.push_back(
        {cp.vertex, cp.collider, (t * ((xk[vi] - xn[vi]) - cp.motion)).norm() / h, cp.k * gap});
  }
  if (collidersOn()) {
    const auto start = Clock::now();
    const ColliderSet& set = *contact.colliders;
    for (std::size_t i = 0; i < vertexCount; ++i) {
      if (freeIndex[i] < 0) continue;
      if (const auto c = set.nearest(xk[i], dist); c && c->distance < minGap) {
        const Vec3 surfaceVelocity = set.surfaceDisplacement(c->collider, c->point) / h;
        samples.push_back({static_cast<int>(i), c->collider,
                           ((Mat3::Identity() - c->normal * c->normal.transpose()) *
                            ((xk[i] - xn[i]) / h - surfaceVelocity))
                               .norm(),
                           kContactScale * mass[i] / (h * h) * (dist - c->distance)});
        xk[i] += (dist - c->distance) * c->normal;
        pushed.push_back({i, c->normal, surfaceVelocity});
      }
    }
    // Faces a probe came through or too near: the triangle moves out.
    for (const FaceContact& fc : faceContacts) {
      const auto& tri = triangles[static_cast<std::size_t>(fc.triangle)];
      const std::array<Vec3, 3> corner{xk[static_cast<std::size_t>(tri[0])],
                                       xk[static_cast<std::size_t>(tri[1])],
                                       xk[static_cast<std::size_t>(tri[2])]};
      const std::array<double, 3> w =
          closestBarycentricOnTriangle(fc.probe, corner[0], corner[1], corner[2]);
      const Vec3 q = w[0] * corner[0] + w[1] * corner[1] + w[2] * corner[2];
      const double along = fc.normal.dot(q - fc.probe);
      const double gap = fc.radius + dist - along;
      if (along < fc.radius + minGap) {
        const Vec3 surfaceVelocity = set.surfaceDisplacement(fc.collider, fc.probe) / h;
        std::size_t heaviest = 0;
        for (std::size_t a = 0; a < 3; ++a) {
          if (w[a] > w[heaviest]) heaviest = a;
          const auto v = static_cast<std::size_t>(tri[a]);
          if (freeIndex[v] < 0) continue;
          xk[v] += gap * fc.normal;
          pushed.push_back({v, fc.normal, surfaceVelocity});
        }
        samples.push_back({tri[heaviest], fc.collider, 0.0, fc.k * gap});
      } else if (gap > 0.0) {
        std::size_t heaviest = 0;
        for (std::size_t a = 1; a < 3; ++a)
          if (w[a] > w[heaviest]) heaviest = a;
        samples.push_back({tri[heaviest], fc.collider, 0.0, fc.k * gap});
      }
    }
    stats.contactMs += since(start);
  }
  if (!selfPairs.empty()) {
    const auto start = Clock::now();
    for (const SelfContactPair& p : selfPairs) {
      const auto vi = static_cast<std::size_t>(p.vertex);
      const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
      const Vec3& a = xk[static_cast<std::size_t>(t[0])];
      const Vec3& b = xk[static_cast<std::size_t>(t[1])];
      const Vec3& c = xk[static_cast<std::size_t>(t[2])];
      const Vec3 q = closestPointOnTriangle(xk[vi], a, b, c);
      const Vec3 d = xk[vi] - q;
      const double gap = d.norm();
      const double side = d.dot(p.normal);
      // Through the triangle: the closest point is inside it and the vertex
      // is on the other side of where it started.
      const Vec3 face = (b - a).cross(c - a);
      const bool inside =
          face.norm() > 0.0 && std::abs(d.normalized().dot(face.normalized())) > 1.0 - 1e-9;
      const bool through = side < 0.0 && inside;
      if (gap >= minGap && !through) continue;
      const Vec3 out = (side >= 0.0 && gap > 1e-9 * dist) ? Vec3(d / gap) : p.normal;
      Vec3 surfaceVelocity = Vec3::Zero();
      for (std::size_t k = 0; k < 3; ++k) {
        const auto j = static_cast<std::size_t>(t[k]);
        surfaceVelocity += p.weights[k] * (xk[j] - xn[j]) / h;
      }
      samples.push_back(
          {p.vertex, -1,
           ((Mat3::Identity() - out * out.transpose()) * ((xk[vi] - xn[vi]) / h - surfaceVelocity))
               .norm(),
           kContactScale * mass[vi] / (h * h) * std::max(0.0, dist - gap)});
      xk[vi] = q + dist * out;
      pushed.push_back({vi, out, surfaceVelocity});
    }
    stats.selfContactMs += since(start);
  }
  mergeContactSamples(samples);
  lastContacts = std::move(samples);
}

void mergeContactSamples(std::vector<ContactSample>& samples) {
  std::sort(samples.begin(), samples.end(), [](const ContactSample& l, const ContactSample& r) {
    return l.vertex != r.vertex ? l.vertex < r.vertex : l.collider < r.collider;
  });
  std::vector<ContactSample> merged;
  merged.reserve(samples.size());
  for (const ContactSample& s : samples) {
    if (!merged.empty() && merged.back().vertex == s.vertex &&
        merged.back().collider == s.collider) {
      merged.back().normalForce += s.normalForce;
      merged.back().slideSpeed = std::max(merged.back().slideSpeed, s.slideSpeed);
    } else {
      merged.push_back(s);
    }
  }
  samples = std::move(merged);
}

void ElasticSheet::setContacts(ContactOptions options) {
  const bool any = (options.colliders != nullptr && options.colliders->size() > 0) ||
                   options.self != SelfContactMode::Off;
  if (any && !(options.distance > 0.0 && std::isfinite(options.distance)))
    throw std::invalid_argument("ElasticSheet::setContacts: contact distance must be > 0");
  if (!(options.selfFriction >= 0.0) || !std::isfinite(options.selfFriction))
    throw std::invalid_argument("ElasticSheet::setContacts: friction must be finite and >= 0");
  if (!(options.foldSpread > 0.0) || !std::isfinite(options.foldSpread))
    throw std::invalid_argument("ElasticSheet::setContacts: fold spread must be > 0");
  if (impl_->selfDetector && options.distance != impl_->contact.distance)
    impl_->selfDetector.reset();
  impl_->contact = std::move(options);
  impl_->lastContacts.clear();
}

void saveContactSamples(StateWriter& out, const std::vector<ContactSample>& samples) {
  out.count(samples.size());
  for (const auto& c : samples) {
    out.i32(c.vertex);
    out.i32(c.collider);
    out.f64(c.slideSpeed);
    out.f64(c.normalForce);
  }
}

std::vector<ContactSample> restoreContactSamples(StateReader& in, std::size_t vertexCount) {
  std::vector<ContactSample> samples(in.count(24));
  for (auto& c : samples) {
    c.vertex = in.i32();
    c.collider = in.i32();
    c.slideSpeed = in.f64();
    c.normalForce = in.f64();
    if (c.vertex < 0 || static_cast<std::size_t>(c.vertex) >= vertexCount)
      in.fail("a contact's vertex is out of range");
  }
  return samples;
}

}  // namespace crumple::sim
