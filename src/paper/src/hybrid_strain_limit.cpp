// Paper stays paper after every animation step of the crumpling model:
// HybridSheet's strain-limit stage (strain_limit.hpp, docs/CRUMPLING.md
// "Strain limit"), with the contacts as constraints it keeps.
#include <algorithm>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/index.hpp"
#include "crumple/paper/strain_limit.hpp"
#include "hybrid_sheet_impl.hpp"

namespace crumple::paper {

using detail::allFinite;

// The geometric step (S_G remeshing, cone fits, S_P rebuild and isometry,
// paper Fig. 16 (c)-(h)) is transactional under the strain bound: when it
// leaves S_P over maxEdgeStrain and more strained than the elastic step
// left the step's own S_P, it is undone, and the elastic step's S_P goes on
// to the limit (docs/CRUMPLING.md "The geometric step under the bound").
// Returns true when it was undone.
bool HybridSheet::Impl::undoStretchingGeometry(const mesh::SheetMesh& spBefore,
                                               const GeometricMesh& sgBefore,
                                               const std::vector<Vec3>& elasticX,
                                               const std::vector<Vec3>& elasticV,
                                               std::vector<Vec3>& positions,
                                               HybridStepStats& stats) {
  Impl& m = *this;
  const double bound = m.params.maxEdgeStrain;
  if (elasticX.size() != spBefore.positions.size() || sgBefore.vertices.size() > elasticX.size())
    return false;
  const double geometric =
      LengthProjector(m.sp.mesh.pattern, m.sp.mesh.triangles).strain(positions).first;
  if (geometric <= bound) return false;
  const double elastic =
      LengthProjector(spBefore.pattern, spBefore.triangles).strain(elasticX).first;
  if (elastic >= geometric) return false;
  GeometricMesh stepped = m.sg;
  m.sg = sgBefore;
  for (std::size_t i = 0; i < m.sg.vertices.size(); ++i) {
    m.sg.vertices[i].position = elasticX[i];
    m.sg.vertices[i].velocity = elasticV[i];
  }
  m.rebuildPhysical();
  if (m.sp.mesh.triangles != spBefore.triangles || m.sp.mesh.pattern != spBefore.pattern) {
    // S_P does not come back as it was: the step's structure stays.
    m.sg = std::move(stepped);
    m.rebuildPhysical();
    return false;
  }
  positions = elasticX;
  stats.topologyChanged = false;
  ++stats.undoneByBound;
  stats.geometric.notes.push_back("the geometric step undone: it left S_P strained by " +
                                  std::to_string(geometric) + ", the elastic step by " +
                                  std::to_string(elastic));
  return true;
}

// Counts S_P's edges through another layer at both (SelfContactDetector::
// crossings).
bool HybridSheet::Impl::passesThroughItself(const std::vector<Vec3>& x0,
                                            const std::vector<Vec3>& x1) const {
  const double h = crossingGuard();
  if (!(h > 0.0) || x0.size() != x1.size()) return false;
  sim::SelfContactDetector detector(sp.mesh.triangles, sp.mesh.pattern, h);
  return detector.crossings(x1).size() > detector.crossings(x0).size();
}

// The largest fraction of the move from x0 to x1 (S_P's current mesh) that
// passes no more edges through another layer than x0 had, by bisection to
// 1/64 of the move: a discrete stand-in for continuous collision detection
// (Bridson et al. 2002, Sec. 7) that stops the sheet where it would pass
// through itself. With `fromRigidMotion` the move starts instead from the
// rigid motion that best takes x0 to x1 (Kabsch 1976: fitRigidMotion), which
// passes no edge through another layer, so only the crossing part of the
// bending is given up. x1 becomes that point of the move; returns the
// fraction.
double HybridSheet::Impl::keepMoveOutOfItself(const std::vector<Vec3>& x0, std::vector<Vec3>& x1,
                                              bool fromRigidMotion) const {
  const double h = crossingGuard();
  if (!(h > 0.0) || x0.size() != x1.size()) return 1.0;
  sim::SelfContactDetector detector(sp.mesh.triangles, sp.mesh.pattern, h);
  const auto crossings = [&](const std::vector<Vec3>& x) { return detector.crossings(x).size(); };
  const std::size_t allowed = crossings(x0);
  if (crossings(x1) <= allowed) return 1.0;
  std::vector<Vec3> rigid;
  if (fromRigidMotion) {
    const RigidMotion motion = fitRigidMotion(x0, x1);
    rigid.resize(x0.size());
    for (std::size_t i = 0; i < x0.size(); ++i) rigid[i] = motion.apply(x0[i]);
    // A rigid motion keeps every crossing as it was, up to rounding: checked.
    if (crossings(rigid) > allowed) rigid.clear();
  }
  const std::vector<Vec3>& from = rigid.empty() ? x0 : rigid;
  const auto at = [&](double alpha) {
    std::vector<Vec3> x(from.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = from[i] + alpha * (x1[i] - from[i]);
    return x;
  };
  constexpr int kBisections = 6;  // to 1/64 of the move
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < kBisections; ++k) {
    const double mid = 0.5 * (lo + hi);
    (crossings(at(mid)) <= allowed ? lo : hi) = mid;
  }
  x1 = at(lo);
  return lo;
}

// The elastic step's self-contact is vertex against triangle, and S_P's
// edges (centimetres long on a sheet a tenth of a millimetre thick) pass
// through each other with no vertex near another layer: the step is cut
// back where it would pass S_P through itself (keepMoveOutOfItself), its
// velocities to the move it made (docs/CRUMPLING.md "Self-contact in the
// crumpling samples"). A sheet no handle or grip holds keeps the rigid part
// of its move, so a sheet in free flight falls and turns on instead of
// standing still in the air (docs/CRUMPLING.md "A sheet in free flight").
double HybridSheet::Impl::keepElasticStepOutOfItself(const std::vector<Vec3>& x0, double dt,
                                                     bool held) {
  std::vector<Vec3> x = elastic->positions();
  const double alpha = keepMoveOutOfItself(x0, x, !held);
  if (alpha >= 1.0) return alpha;
  std::vector<Vec3> v(x.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = (x[i] - x0[i]) / dt;
  elastic->setPositions(x);
  elastic->setVelocities(v);
  return alpha;
}

// A grip follows its anchor handle: by as much as catchUpPins keeps the
// handle from its node, so a lagging finger's patch lags with it.
sim::GripFunction HybridSheet::Impl::laggingGrips(const sim::PinFunction& pins,
                                                  const sim::PinFunction& nodePins) const {
  if (!grips) return {};
  return [this, pins, nodePins](double t, std::vector<sim::Grip>& out) {
    grips(t, out);
    if (out.empty()) return;  // no finger holds a patch: nothing to pay for
    std::vector<sim::Pin> now, nodes;
    pins(t, now);
    nodePins(t, nodes);
    for (sim::Grip& g : out) {
      const auto at = [&](const std::vector<sim::Pin>& list) {
        return std::find_if(list.begin(), list.end(),
                            [&](const sim::Pin& p) { return p.vertex == g.anchor; });
      };
      const auto a = at(now), b = at(nodes);
      if (a != now.end() && b != nodes.end()) g.position += a->position - b->position;
    }
  };
}

// A lagging handle comes back along the straight line from where the step
// finds it, at most lagCatchUpSpeed faster than its node moves; its
// tangent-plane pins (listed after it, HandleRig::pins) keep their offsets
// from it. Without this the first step whose structure lets the sheet follow
// again closes the whole lag at once, and the sheet jumps (docs/CRUMPLING.md
// "Popping").
sim::PinFunction HybridSheet::Impl::catchUpPins(double t, double dt,
                                                const sim::PinFunction& pins) const {
  const double speed = params.lagCatchUpSpeed;
  // Lags exist, and are reported, only under the strain limit.
  if (!(speed > 0.0) || !(dt > 0.0) || !(params.maxEdgeStrain > 0.0)) return pins;
  std::vector<sim::Pin> before, after;
  pins(t, before);
  pins(t + dt, after);
  struct Path {
    int vertex = -1;
    Vec3 from, to;  // where the handle is at t, where it may be at t + dt
  };
  std::vector<Path> paths;
  for (const sim::Pin& p : after) {
    if (!isHandle(p.vertex) || !inRange(sp.mesh.positions, p.vertex)) continue;
    const Vec3 start = sp.mesh.positions[idx(p.vertex)];
    const auto node = std::find_if(before.begin(), before.end(),
                                   [&](const sim::Pin& q) { return q.vertex == p.vertex; });
    // A handle that takes hold in this step starts from where its vertex is.
    const double nodeMove = node == before.end() ? 0.0 : (p.position - node->position).norm();
    const double allowed = nodeMove + speed * dt;
    const Vec3 gap = p.position - start;
    const double distance = gap.norm();
    if (distance <= allowed) continue;
    paths.push_back({p.vertex, start, start + gap * (allowed / distance)});
  }
  if (paths.empty()) return pins;
  return [pins, paths = std::move(paths), t, dt, this](double tau, std::vector<sim::Pin>& out) {
    pins(tau, out);
    const double s = std::clamp((tau - t) / dt, 0.0, 1.0);
    Vec3 shift = Vec3::Zero();
    for (sim::Pin& p : out) {
      if (isHandle(p.vertex)) {
        const auto path = std::find_if(paths.begin(), paths.end(),
                                       [&](const Path& q) { return q.vertex == p.vertex; });
        shift = path == paths.end() ? Vec3::Zero()
                                    : Vec3(path->from + s * (path->to - path->from) - p.position);
      }
      p.position += shift;
    }
  };
}

// Each handle's lag behind its node, not behind the caught-up target the
// step was given (catchUpPins).
void HybridSheet::Impl::measureLags(const std::vector<sim::Pin>& nodes, const std::vector<Vec3>& x,
                                    StrainLimitStats& s) const {
  s.lag = 0.0;
  s.lagVertex = -1;
  s.handleLags.clear();
  for (const sim::Pin& p : nodes) {
    if (!isHandle(p.vertex) || !inRange(x, p.vertex)) continue;
    const double d = (x[idx(p.vertex)] - p.position).norm();
    s.handleLags.emplace_back(p.vertex, d);
    if (d > s.lag) {
      s.lag = d;
      s.lagVertex = p.vertex;
    }
  }
}

// Paper stays paper after the isometry (strain_limit.hpp): S_P within
// maxEdgeStrain, the handles on their targets or lagging; a remeshing that
// leaves no configuration within the bound is undone.
void HybridSheet::Impl::limitStepStrain(const mesh::SheetMesh& spBefore,
                                        const GeometricMesh& sgBefore,
                                        const std::vector<sim::Pin>& pinned, int frame,
                                        std::vector<Vec3>& positions, HybridStepStats& stats) {
  Impl& m = *this;
  // The handle vertices and their targets (tangent-plane pins bind in the
  // elastic step only).
  std::vector<int> handles, tangentPins;
  std::vector<Vec3> targets;
  for (const sim::Pin& p : pinned) {
    const bool handle = m.isHandle(p.vertex);
    if (inRange(positions, p.vertex) && !handle) tangentPins.push_back(p.vertex);
    if (!handle || !inRange(spBefore.positions, p.vertex)) continue;
    handles.push_back(p.vertex);
    targets.push_back(p.position);
  }
  std::vector<KeepOut> keepOut;  // the contacts the limit keeps
  const auto limit = [&] {
    const bool sameMesh =
        spBefore.triangles == m.sp.mesh.triangles && spBefore.pattern == m.sp.mesh.pattern;
    return limitStrain(
        {m.sp.mesh.pattern, m.sp.mesh.triangles, spBefore.pattern, spBefore.triangles,
         spBefore.positions, sameMesh, handles, targets, tangentPins, m.params.maxEdgeStrain,
         m.params.strainLimitIterations, keepOut, m.crossingGuard()},
        positions);
  };
  // Contacts as constraints of the limit: the failsafe's moves are kept
  // (KeepOut), and failsafe and limit alternate while the failsafe breaks
  // the bound again (alternating projections, von Neumann 1950).
  // The failsafe moves vertex by vertex, and a collider pressing on a stack
  // can push one layer through the next: it is cut back like the other
  // stages (keepMoveOutOfItself), its half-spaces where it stopped.
  const auto contactRound = [&] {
    if (!m.contactsOn()) return false;
    const std::vector<Vec3> before = positions;
    auto more =
        keepOutOfContacts(m.contact, m.sp.mesh.triangles, m.sp.mesh.pattern, m.heldBy(pinned),
                          positions, &stats.ms.contacts, &stats.ms.selfContacts);
    if (!more.empty()) {
      const double alpha = m.keepMoveOutOfItself(before, positions);
      if (!(alpha > 0.0)) more.clear();
      for (KeepOut& k : more) k.point = positions[idx(k.vertex)];
    }
    keepOut.insert(keepOut.end(), more.begin(), more.end());
    return !more.empty();
  };
  const auto again = [&] {
    const StrainLimitStats first = stats.strainLimit;
    stats.strainLimit = limit();
    stats.strainLimit.iterations += first.iterations;
    stats.strainLimit.maxBefore = first.maxBefore;
    stats.strainLimit.ran = stats.strainLimit.ran || first.ran;
    stats.strainLimit.droppedKeepOut = stats.strainLimit.droppedKeepOut || first.droppedKeepOut;
  };
  contactRound();
  stats.strainLimit = limit();
  if (stats.strainLimit.maxAfter > m.params.maxEdgeStrain && stats.topologyChanged &&
      !spBefore.positions.empty()) {
    // The new structure leaves S_P no configuration within the bound from
    // any start, while the step's start was within it (also when S_G now
    // has more vertices than the step's S_P had): the step's remeshing
    // is undone (transactional, like the cone fits above) and the sheet as
    // it was lags instead; the cooldown keeps the region from being remeshed
    // again at once.
    m.sg = sgBefore;
    m.rebuildPhysical();
    ++stats.undoneByBound;
    keepOut.clear();  // its vertices were the undone S_P's
    if (m.sp.mesh.triangles == spBefore.triangles && m.sp.mesh.pattern == spBefore.pattern) {
      // From the step's start as it was, its handles where they were: put
      // on their targets at once they could pass edges through another
      // layer, which the limit would then keep (the limit moves them on).
      positions = spBefore.positions;
      contactRound();
      again();
      stats.geometric.notes.push_back(
          "the step's remeshing undone: S_P had no configuration "
          "within max_edge_strain");
    } else {
      // S_P came out of the step's S_G other than it was at the step's
      // start: the sheet as rebuilt there, whose vertices `positions` are.
      positions = m.sp.mesh.positions;
    }
  }
  const LengthProjector lengths(m.sp.mesh.pattern, m.sp.mesh.triangles);
  // Until the failsafe moves nothing (one pass can push a vertex out of one
  // layer into another), the limit again wherever it broke the bound.
  constexpr int kContactRounds = 8;
  for (int round = 0; round < kContactRounds && contactRound(); ++round) {
    if (lengths.strain(positions).first > m.params.maxEdgeStrain) again();
  }
  // A sheet rebuilt by an undone remeshing (whose S_P differs from the
  // step's start) has not been through the limit yet when no contact moved.
  if (lengths.strain(positions).first > m.params.maxEdgeStrain) again();
  if (!allFinite(positions)) throw NumericalError("strain limit", frame, "non-finite positions");
}

}  // namespace crumple::paper
