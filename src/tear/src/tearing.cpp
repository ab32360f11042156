#include "crumple/tear/tearing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "crumple/core/geometry2d.hpp"
#include "crumple/tear/candidates.hpp"

namespace crumple::tear {

namespace {

double meanEdgeLength(const mesh::SheetMesh& m) {
  double sum = 0.0;
  long count = 0;
  for (const auto& e : mesh::buildEdges(m)) {
    sum +=
        (m.pattern[static_cast<std::size_t>(e.v[1])] - m.pattern[static_cast<std::size_t>(e.v[0])])
            .norm();
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

FiberTexture fibersOver(const mesh::SheetMesh& m, FiberTextureParams params, std::uint64_t seed) {
  if (m.pattern.empty()) throw std::invalid_argument("Tearing: an empty mesh");
  Vec2 lo = m.pattern.front(), hi = m.pattern.front();
  for (const Vec2& p : m.pattern) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  params.seed = seed;
  const Vec2 margin = Vec2::Constant(2.0 * params.texelSize);
  return FiberTexture(lo - margin, hi - lo + 2.0 * margin, params);
}

// A blend over the mesh before one cut, re-expressed over the mesh before
// the frame: vertices appended earlier in the frame through their blends
// (`earlier`, vertex index = count + k), vertices moved earlier in the frame
// through theirs. More than three terms (cuts of one frame in the same
// triangles) keep the three heaviest, renormalised.
VertexBlend resolve(const VertexBlend& b, std::size_t count,
                    const std::vector<VertexBlend>& earlier,
                    const std::vector<std::pair<int, VertexBlend>>& moved) {
  std::vector<std::pair<int, double>> terms;
  const auto expand = [&](const VertexBlend& e, double w) {
    for (int k = 0; k < 3; ++k)
      if (e.vertex[static_cast<std::size_t>(k)] >= 0)
        terms.emplace_back(e.vertex[static_cast<std::size_t>(k)],
                           w * e.weight[static_cast<std::size_t>(k)]);
  };
  for (int j = 0; j < 3; ++j) {
    const int v = b.vertex[static_cast<std::size_t>(j)];
    if (v < 0) continue;
    const double w = b.weight[static_cast<std::size_t>(j)];
    if (static_cast<std::size_t>(v) >= count) {
      expand(earlier.at(static_cast<std::size_t>(v) - count), w);
      continue;
    }
    const auto it =
        std::find_if(moved.begin(), moved.end(), [&](const auto& m) { return m.first == v; });
    if (it != moved.end()) {
      expand(it->second, w);
    } else {
      terms.emplace_back(v, w);
    }
  }
  return makeBlend(std::move(terms));
}

}  // namespace

Tearing::Tearing(const mesh::SheetMesh& mesh, const TearingParams& params, std::uint64_t seed)
    : params_(params),
      fibers_(fibersOver(mesh, params.fibers, seed)),
      edgeLength_(meanEdgeLength(mesh)) {
  if (!(params.minAdvance > 0.0 && params.maxAdvance >= params.minAdvance))
    throw std::invalid_argument("Tearing: need 0 < minAdvance <= maxAdvance");
  if (!(params.griffith.resistance >= 0.0) || !(params.griffith.speed > 0.0) ||
      !(params.griffith.tipDamage >= 0.0 && params.griffith.tipDamage <= 1.0))
    throw std::invalid_argument("Tearing: need resistance >= 0, speed > 0, tip damage in [0, 1]");
  if (params.maxNewTearsPerFrame < 0)
    throw std::invalid_argument("Tearing: maxNewTearsPerFrame must be >= 0");
  if (!(edgeLength_ > 0.0)) throw std::invalid_argument("Tearing: a mesh without edges");
  if (!(params.branchAngle >= 0.0))
    throw std::invalid_argument("Tearing: branchAngle must be >= 0");
}

TearFrameResult Tearing::step(mesh::SheetMesh& mesh, const std::vector<int>& junctions,
                              const std::vector<char>& held, const VertexForces& forces) {
  TearFrameResult result;
  result.vertexCountBefore = mesh.vertexCount();
  std::vector<int> activeTips;
  for (int v : tips_)
    if (v >= 0) activeTips.push_back(v);
  result.tests =
      testCandidates(mesh, fibers_, activeTips, junctions, held, forces, params_.griffith);
  // A tear's lips are not new candidates: the kinks of their chains are not
  // corners of the paper's outline.
  lip_.resize(mesh.vertexCount(), 0);
  std::erase_if(result.tests, [&](const CandidateTest& t) {
    return t.candidate.kind != CandidateKind::Tip &&
           lip_[static_cast<std::size_t>(t.candidate.vertex)] != 0;
  });

  // What advances this frame: every tip that tears, then the strongest new
  // starts (by E_r / E_f, then vertex).
  struct Advance {
    const CandidateTest* test;
    int tear;
  };
  std::vector<Advance> advances;
  std::vector<const CandidateTest*> starts;
  for (const CandidateTest& t : result.tests) {
    if (!t.tears) continue;
    if (t.candidate.kind == CandidateKind::Tip) {
      const auto it = std::find(tips_.begin(), tips_.end(), t.candidate.vertex);
      advances.push_back({&t, static_cast<int>(it - tips_.begin())});
    } else {
      starts.push_back(&t);
    }
  }
  const auto strength = [](const CandidateTest* t) {
    return t->propagation.energyRelease / std::max(t->fractureEnergy, 1e-300);
  };
  std::stable_sort(
      starts.begin(), starts.end(),
      [&](const CandidateTest* a, const CandidateTest* b) { return strength(a) > strength(b); });
  for (std::size_t k = 0; k < starts.size() && static_cast<int>(k) < params_.maxNewTearsPerFrame;
       ++k)
    advances.push_back({starts[k], -1});

  // Each boundary vertex's neighbours along the outline (for minStartAngle).
  std::vector<std::array<int, 2>> around;
  if (params_.minStartAngle > 0.0) {
    around.assign(mesh.vertexCount(), {-1, -1});
    for (const auto& loop : boundaryLoops(mesh))
      for (std::size_t k = 0; k < loop.size(); ++k)
        around[static_cast<std::size_t>(loop[k])] = {loop[(k + loop.size() - 1) % loop.size()],
                                                     loop[(k + 1) % loop.size()]};
  }
  for (const Advance& a : advances) {
    const CandidateTest& t = *a.test;
    const Vec2 from = mesh.pattern[static_cast<std::size_t>(t.candidate.vertex)];
    if (a.tear >= 0 && params_.maxTurn < std::numbers::pi) {
      const auto last = std::find_if(segments_.rbegin(), segments_.rend(),
                                     [&](const TearSegment& seg) { return seg.tear == a.tear; });
      if (last != segments_.rend()) {
        const Vec2 before = last->cut.back() - last->cut.front();
        const Vec2& d = t.propagation.direction;
        const double turn = std::atan2(std::abs(cross2(before, d)), before.dot(d));
        if (turn > params_.maxTurn) {
          result.skipped.push_back("vertex " + std::to_string(t.candidate.vertex) +
                                   ": the tear would turn back by " +
                                   std::to_string(turn * 180.0 / std::numbers::pi) + " deg");
          continue;
        }
      }
    }
    if (a.tear < 0 && params_.minStartAngle > 0.0) {
      double angle = std::numbers::pi;
      for (int n : around[static_cast<std::size_t>(t.candidate.vertex)]) {
        if (n < 0) continue;
        const Vec2 along = mesh.pattern[static_cast<std::size_t>(n)] - from;
        const Vec2& d = t.propagation.direction;
        angle = std::min(angle, std::atan2(std::abs(cross2(along, d)), along.dot(d)));
      }
      if (angle < params_.minStartAngle) {
        result.skipped.push_back(
            "vertex " + std::to_string(t.candidate.vertex) + ": it would start " +
            std::to_string(angle * 180.0 / std::numbers::pi) + " deg from the outline");
        continue;
      }
    }
    // s_{t+1} = s_t + V E_r d_prop (thesis 3.3.3), the step held to what the mesh can show.
    const double length =
        std::clamp(params_.griffith.speed * t.propagation.energyRelease,
                   params_.minAdvance * edgeLength_, params_.maxAdvance * edgeLength_);
    TearEvent e;
    e.tear = a.tear;
    e.kind = t.candidate.kind;
    e.energyRelease = t.propagation.energyRelease;
    e.fractureEnergy = t.fractureEnergy;
    (void)cutTo(mesh, t.candidate.vertex, from + length * t.propagation.direction, e, held, result);
  }
  return result;
}

bool Tearing::cutTo(mesh::SheetMesh& mesh, int vertex, const Vec2& to, TearEvent e,
                    const std::vector<char>& held, TearFrameResult& result) {
  mesh::SheetMesh trial = mesh;
  CutResult cut;
  try {
    CutOptions options;
    options.snap = params_.snap;
    options.fixed = &held;
    cut = cutAlong(trial, vertex, to, options);
  } catch (const std::invalid_argument& ex) {
    // The direction leaves the sheet here: no tear from this point.
    result.skipped.push_back("vertex " + std::to_string(vertex) + ": " + ex.what());
    return false;
  }
  if (cut.chain.size() < 2) {
    result.skipped.push_back("vertex " + std::to_string(vertex) + ": the cut snaps back onto it");
    return false;
  }
  mesh = std::move(trial);
  lip_.resize(mesh.vertexCount(), 0);
  for (int v : cut.chain) lip_[static_cast<std::size_t>(v)] = 1;
  for (int v : cut.twins) lip_[static_cast<std::size_t>(v)] = 1;
  // Thesis Fig. 3.20: where the tear turns at s_t by more than eps_a, s_t is
  // split into two boundary points, one of them an inward corner: a point
  // the tear may branch from. Where it runs on straight, s_t is just part of
  // the lips.
  if (e.tear >= 0 && !cut.twins.empty()) {
    const auto last = std::find_if(segments_.rbegin(), segments_.rend(),
                                   [&](const TearSegment& seg) { return seg.tear == e.tear; });
    if (last != segments_.rend() && last->cut.size() >= 2) {
      const Vec2 before = last->cut.back() - last->cut.front();
      const Vec2 after = mesh.pattern[static_cast<std::size_t>(cut.chain.back())] -
                         mesh.pattern[static_cast<std::size_t>(cut.chain.front())];
      const double turn =
          std::atan2(std::abs(before.x() * after.y() - before.y() * after.x()), before.dot(after));
      if (turn > params_.branchAngle) {
        lip_[static_cast<std::size_t>(cut.chain.front())] = 0;
        lip_[static_cast<std::size_t>(cut.twins.front())] = 0;
      }
    }
  }
  // Moved vertices first: appended ones' blends may name them.
  std::vector<std::pair<int, VertexBlend>> moved;
  for (const auto& [v, b] : cut.relocated)
    moved.emplace_back(v, resolve(b, result.vertexCountBefore, result.blends, result.relocated));
  for (const VertexBlend& b : cut.blends)
    result.blends.push_back(resolve(b, result.vertexCountBefore, result.blends, result.relocated));
  for (const auto& [v, b] : moved) {
    if (static_cast<std::size_t>(v) >= result.vertexCountBefore) {
      result.blends[static_cast<std::size_t>(v) - result.vertexCountBefore] = b;
      continue;
    }
    const int vertex = v;  // a plain local for the lambda (clang 14 cannot capture a binding)
    const auto it = std::find_if(result.relocated.begin(), result.relocated.end(),
                                 [&](const auto& m) { return m.first == vertex; });
    if (it != result.relocated.end()) {
      it->second = b;
    } else {
      result.relocated.emplace_back(v, b);
    }
  }
  e.started = e.tear < 0;
  if (e.started) {
    e.tear = static_cast<int>(tips_.size());
    tips_.push_back(-1);
    startKinds_.push_back(e.kind);
  }
  tips_[static_cast<std::size_t>(e.tear)] = cut.separated ? -1 : cut.tip;
  e.vertex = vertex;
  e.from = mesh.pattern[static_cast<std::size_t>(cut.chain.front())];
  e.to = mesh.pattern[static_cast<std::size_t>(cut.chain.back())];
  e.separated = cut.separated;
  result.events.push_back(e);
  TearSegment seg;
  seg.tear = e.tear;
  for (int v : cut.chain) seg.cut.push_back(mesh.pattern[static_cast<std::size_t>(v)]);
  seg.detail = detailPath(fibers_, e.from, e.to, params_.detail);
  segments_.push_back(std::move(seg));
  return true;
}

void Tearing::rebind(const mesh::SheetMesh& mesh, double lipTolerance) {
  std::vector<int> boundary;
  for (const auto& loop : boundaryLoops(mesh))
    boundary.insert(boundary.end(), loop.begin(), loop.end());
  double extent = 0.0;
  for (const Vec2& q : mesh.pattern) extent = std::max(extent, q.cwiseAbs().maxCoeff());
  const double same = 1e-9 * std::max(extent, 1e-3);
  const auto at = [&](int v) -> const Vec2& { return mesh.pattern[static_cast<std::size_t>(v)]; };
  for (std::size_t tear = 0; tear < tips_.size(); ++tear) {
    if (tips_[tear] < 0) continue;
    const auto last = std::find_if(segments_.rbegin(), segments_.rend(), [&](const TearSegment& s) {
      return s.tear == static_cast<int>(tear);
    });
    const Vec2 tip = last->cut.back();
    const auto it = std::find_if(boundary.begin(), boundary.end(),
                                 [&](int v) { return (at(v) - tip).norm() <= same; });
    if (it == boundary.end())
      throw std::runtime_error("Tearing::rebind: tear " + std::to_string(tear) +
                               "'s tip is not a boundary vertex of the mesh");
    tips_[tear] = *it;
  }
  lip_.assign(mesh.vertexCount(), 0);
  for (const TearSegment& s : segments_)
    for (int v : boundary)
      for (std::size_t k = 0; k + 1 < s.cut.size(); ++k)
        if (distanceToSegment(at(v), s.cut[k], s.cut[k + 1]) <= lipTolerance) {
          lip_[static_cast<std::size_t>(v)] = 1;
          break;
        }
  // Thesis Fig. 3.20: a former tip where the tear turned by more than eps_a
  // is a point it may branch from.
  for (std::size_t i = 0; i < segments_.size(); ++i)
    for (std::size_t j = i + 1; j < segments_.size(); ++j) {
      if (segments_[j].tear != segments_[i].tear) continue;
      const Vec2 before = segments_[i].cut.back() - segments_[i].cut.front();
      const Vec2 after = segments_[j].cut.back() - segments_[j].cut.front();
      const double turn = std::atan2(std::abs(cross2(before, after)), before.dot(after));
      if (turn > params_.branchAngle)
        for (int v : boundary)
          if ((at(v) - segments_[j].cut.front()).norm() <= lipTolerance)
            lip_[static_cast<std::size_t>(v)] = 0;
      break;
    }
}

void Tearing::recut(const std::vector<std::vector<Vec2>>& cuts) {
  if (cuts.size() > segments_.size())
    throw std::invalid_argument("Tearing::recut: more cuts than advances");
  const std::size_t first = segments_.size() - cuts.size();
  const double moved = 0.5 * fibers_.texelSize();
  for (std::size_t k = 0; k < cuts.size(); ++k) {
    if (cuts[k].size() < 2) throw std::invalid_argument("Tearing::recut: a cut needs two points");
    TearSegment& s = segments_[first + k];
    if ((cuts[k].front() - s.detail.front()).norm() > moved ||
        (cuts[k].back() - s.detail.back()).norm() > moved)
      s.detail = detailPath(fibers_, cuts[k].front(), cuts[k].back(), params_.detail);
    s.cut = cuts[k];
  }
}

TearFrameResult Tearing::replay(mesh::SheetMesh& mesh, const std::vector<TearEvent>& events,
                                const std::vector<char>& held) {
  if (!tips_.empty())
    throw std::logic_error("Tearing::replay: only a Tearing without tears replays");
  TearFrameResult result;
  result.vertexCountBefore = mesh.vertexCount();
  std::vector<int> tearOf;  // events' tear ids -> this Tearing's
  for (TearEvent e : events) {
    int vertex = -1;
    const int original = e.tear;
    if (e.started) {
      // The boundary vertex nearest where the tear started.
      double best = std::numeric_limits<double>::infinity();
      for (const auto& loop : boundaryLoops(mesh))
        for (int v : loop) {
          const double d = (mesh.pattern[static_cast<std::size_t>(v)] - e.from).squaredNorm();
          if (d < best) {
            best = d;
            vertex = v;
          }
        }
      e.tear = -1;
    } else {
      if (original < 0 || static_cast<std::size_t>(original) >= tearOf.size() ||
          tearOf[static_cast<std::size_t>(original)] < 0)
        continue;
      e.tear = tearOf[static_cast<std::size_t>(original)];
      vertex = tips_[static_cast<std::size_t>(e.tear)];
      if (vertex < 0) continue;
    }
    const std::size_t before = tips_.size();
    const bool made = cutTo(mesh, vertex, e.to, e, held, result);
    if (e.started) {
      if (tearOf.size() <= static_cast<std::size_t>(original))
        tearOf.resize(static_cast<std::size_t>(original) + 1, -1);
      tearOf[static_cast<std::size_t>(original)] = made ? static_cast<int>(before) : -1;
    }
  }
  return result;
}

std::vector<Vec3> blendValues(const std::vector<Vec3>& values,
                              const std::vector<VertexBlend>& blends,
                              const std::vector<std::pair<int, VertexBlend>>& relocated) {
  const auto apply = [&](const VertexBlend& b) {
    Vec3 v = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      if (b.vertex[static_cast<std::size_t>(k)] >= 0)
        v += b.weight[static_cast<std::size_t>(k)] *
             values.at(static_cast<std::size_t>(b.vertex[static_cast<std::size_t>(k)]));
    return v;
  };
  std::vector<Vec3> out = values;
  for (const auto& [v, b] : relocated) out.at(static_cast<std::size_t>(v)) = apply(b);
  out.reserve(values.size() + blends.size());
  for (const VertexBlend& b : blends) {
    Vec3 v = Vec3::Zero();
    for (int k = 0; k < 3; ++k)
      if (b.vertex[static_cast<std::size_t>(k)] >= 0)
        v += b.weight[static_cast<std::size_t>(k)] *
             values.at(static_cast<std::size_t>(b.vertex[static_cast<std::size_t>(k)]));
    out.push_back(v);
  }
  return out;
}

void Tearing::saveState(StateWriter& out) const {
  out.tag("TEAR");
  out.f64(edgeLength_);
  out.i32s(tips_);
  out.bytes(lip_);
  out.count(startKinds_.size());
  for (auto k : startKinds_) out.u8(static_cast<std::uint8_t>(k));
  out.count(segments_.size());
  for (const auto& s : segments_) {
    out.i32(s.tear);
    out.vec2s(s.cut);
    out.vec2s(s.detail);
  }
}

void Tearing::restoreState(StateReader& in) {
  in.tag("TEAR");
  edgeLength_ = in.f64();
  if (!(edgeLength_ > 0.0)) in.fail("a non-positive edge length");
  tips_ = in.i32s();
  lip_ = in.bytes();
  startKinds_.resize(in.count(1));
  for (auto& k : startKinds_) {
    const std::uint8_t kind = in.u8();
    if (kind > static_cast<std::uint8_t>(CandidateKind::InwardCorner))
      in.fail("a tear's start kind of " + std::to_string(kind));
    k = static_cast<CandidateKind>(kind);
  }
  segments_.resize(in.count(20));
  for (auto& s : segments_) {
    s.tear = in.i32();
    s.cut = in.vec2s();
    s.detail = in.vec2s();
  }
  if (tips_.size() != startKinds_.size()) in.fail("the tears' tips do not match their starts");
}

}  // namespace crumple::tear
