#include "crumple/pipeline/inspect.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/core/error.hpp"
#include "crumple/sim/self_contact.hpp"
#include "json_writer.hpp"

namespace crumple::pipeline {

AngleDefect angleDefect(const std::vector<std::array<int, 3>>& triangles,
                        const std::vector<Vec3>& positions, const std::vector<int>& excluded) {
  const std::size_t n = positions.size();
  std::vector<double> angleSum(n, 0.0);
  std::vector<char> skip(n, 0);
  for (const int v : excluded)
    if (v >= 0 && static_cast<std::size_t>(v) < n) skip[static_cast<std::size_t>(v)] = 1;
  // Edges used by one triangle only bound the mesh (the outline, a tear's lips).
  std::map<std::pair<int, int>, int> edgeUses;
  for (const auto& tri : triangles)
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      ++edgeUses[{std::min(a, b), std::max(a, b)}];
      const Vec3& x = positions[static_cast<std::size_t>(tri[k])];
      const Vec3 e0 = positions[static_cast<std::size_t>(b)] - x;
      const Vec3 e1 = positions[static_cast<std::size_t>(tri[(k + 2) % 3])] - x;
      angleSum[static_cast<std::size_t>(a)] += std::atan2(e0.cross(e1).norm(), e0.dot(e1));
    }
  std::vector<char> used(n, 0);
  for (const auto& tri : triangles)
    for (const int v : tri) used[static_cast<std::size_t>(v)] = 1;
  for (const auto& [edge, uses] : edgeUses)
    if (uses == 1)
      skip[static_cast<std::size_t>(edge.first)] = skip[static_cast<std::size_t>(edge.second)] = 1;
  AngleDefect d;
  for (std::size_t v = 0; v < n; ++v) {
    if (!used[v] || skip[v]) continue;
    const double defect = std::abs(2.0 * std::numbers::pi - angleSum[v]);
    d.total += defect;
    d.max = std::max(d.max, defect);
    ++d.vertices;
  }
  if (d.vertices > 0) d.mean = d.total / static_cast<double>(d.vertices);
  return d;
}

FrameMetrics measureFrame(const cache::FrameRecord& frame) {
  FrameMetrics m;
  m.frame = frame.frame;
  m.time = frame.time;
  m.vertices = frame.positions.size();
  m.triangles = frame.triangles.size();
  if (!frame.positions.empty()) {
    Vec3 lo = frame.positions.front(), hi = lo;
    for (const Vec3& x : frame.positions) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    m.extent = hi - lo;
  }
  // Each edge with the (up to two) triangles beside it.
  std::map<std::pair<int, int>, std::array<int, 2>> edges;
  for (std::size_t t = 0; t < frame.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& tri = frame.triangles[t];
      const int a = tri[static_cast<std::size_t>(k)],
                b = tri[static_cast<std::size_t>((k + 1) % 3)];
      auto [it, added] = edges.try_emplace({std::min(a, b), std::max(a, b)}, std::array{-1, -1});
      it->second[added ? 0 : 1] = static_cast<int>(t);
    }
  const auto normal = [&](int t) {
    const auto& tri = frame.triangles[static_cast<std::size_t>(t)];
    const Vec3& x0 = frame.positions[static_cast<std::size_t>(tri[0])];
    return Vec3((frame.positions[static_cast<std::size_t>(tri[1])] - x0)
                    .cross(frame.positions[static_cast<std::size_t>(tri[2])] - x0));
  };
  double sum = 0.0;
  std::size_t compressed = 0;
  for (const auto& [edge, beside] : edges) {
    const auto [a, b] = edge;
    if (beside[1] >= 0) {
      const Vec3 n0 = normal(beside[0]), n1 = normal(beside[1]);
      m.maxDihedral = std::max(m.maxDihedral, std::atan2(n0.cross(n1).norm(), n0.dot(n1)));
    }
    const double rest =
        (frame.pattern[static_cast<std::size_t>(a)] - frame.pattern[static_cast<std::size_t>(b)])
            .norm();
    const double now = (frame.positions[static_cast<std::size_t>(a)] -
                        frame.positions[static_cast<std::size_t>(b)])
                           .norm();
    const double strain = (now - rest) / rest;
    sum += std::abs(strain);
    m.maxStrain = std::max(m.maxStrain, std::abs(strain));
    if (strain < -0.01) ++compressed;
  }
  if (!edges.empty()) {
    m.cMean = sum / static_cast<double>(edges.size());
    m.nComp = static_cast<double>(compressed) / static_cast<double>(edges.size());
  }
  for (std::size_t h = 0; h < frame.handleVertices.size(); ++h) {
    const int v = frame.handleVertices[h];
    if (v < 0) continue;  // released
    m.handleError =
        std::max(m.handleError,
                 (frame.positions[static_cast<std::size_t>(v)] - frame.handleTargets[h]).norm());
  }
  m.centroid = sheetMoments(frame.triangles, frame.pattern, frame.positions).centroid;
  Vec3 normalSum = Vec3::Zero();
  for (std::size_t t = 0; t < frame.triangles.size(); ++t) normalSum += normal(static_cast<int>(t));
  if (normalSum.norm() > 0.0) {
    m.meanNormal = normalSum.normalized();
    m.normalAngleDeg =
        std::acos(std::clamp(m.meanNormal.y(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  }
  const AngleDefect defect = angleDefect(frame.triangles, frame.positions, frame.singularVertices);
  m.meanAngleDefect = defect.mean;
  m.maxAngleDefect = defect.max;
  m.totalAngleDefect = defect.total;
  m.defectVertices = defect.vertices;
  m.singularVertices = frame.singularVertices.size();
  m.junctionVertices = frame.junctionVertices.size();
  m.tears = frame.tearCount;
  std::optional<std::vector<cache::ContactRecord>> contacts;
  try {
    contacts = cache::decodeContacts(frame.extensions);
    m.structure = cache::decodeStructureChanges(frame.extensions);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError("frame " + std::to_string(frame.frame) + ": " + e.what());
  }
  if (contacts) {
    m.contacts = contacts->size();
    for (const auto& c : *contacts)
      m.maxSlideSpeed = std::max(m.maxSlideSpeed, static_cast<double>(c.slideSpeed));
  }
  return m;
}

SelfPenetration selfPenetration(const cache::FrameRecord& frame, double thickness,
                                const std::vector<char>* vertexMask) {
  SelfPenetration out;
  if (!(thickness > 0.0) || !std::isfinite(thickness) || frame.triangles.empty()) return out;
  sim::SelfContactDetector detector(frame.triangles, frame.pattern, thickness);
  for (const sim::SelfContactPair& p : detector.find(frame.positions, thickness, vertexMask))
    out.depth = std::max(out.depth, (thickness - p.distance) / thickness);
  const auto crossings = detector.crossings(frame.positions);
  out.crossings = crossings.size();
  for (const sim::SelfCrossing& c : crossings)
    out.depth = std::max(out.depth, 1.0 + c.depth / thickness);
  return out;
}

SheetMoments sheetMoments(const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Vec2>& pattern, const std::vector<Vec3>& positions) {
  // Per triangle: its pattern area A, centroid g and, for a uniform density
  // over it, the mean of |x - g|^2, (|a - g|^2 + |b - g|^2 + |c - g|^2) / 12.
  std::vector<double> areas;
  std::vector<Vec3> centroids;
  areas.reserve(triangles.size());
  centroids.reserve(triangles.size());
  double area = 0.0;
  Vec3 first = Vec3::Zero();
  for (const auto& t : triangles) {
    const Vec2 u =
        pattern[static_cast<std::size_t>(t[1])] - pattern[static_cast<std::size_t>(t[0])];
    const Vec2 v =
        pattern[static_cast<std::size_t>(t[2])] - pattern[static_cast<std::size_t>(t[0])];
    const double a = 0.5 * std::abs(u.x() * v.y() - u.y() * v.x());
    const Vec3 g =
        (positions[static_cast<std::size_t>(t[0])] + positions[static_cast<std::size_t>(t[1])] +
         positions[static_cast<std::size_t>(t[2])]) /
        3.0;
    areas.push_back(a);
    centroids.push_back(g);
    area += a;
    first += a * g;
  }
  SheetMoments m;
  if (!(area > 0.0)) return m;
  m.centroid = first / area;
  // Two passes: distances to the centroid, not a difference of large squares.
  double second = 0.0;
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const Vec3& g = centroids[k];
    double spread = 0.0;
    for (const int v : triangles[k])
      spread += (positions[static_cast<std::size_t>(v)] - g).squaredNorm();
    second += areas[k] * ((g - m.centroid).squaredNorm() + spread / 12.0);
  }
  m.gyration = std::sqrt(second / area);
  return m;
}

double poppingMeasure(const cache::FrameRecord& previous, const cache::FrameRecord& current) {
  const SheetMoments a = sheetMoments(previous.triangles, previous.pattern, previous.positions);
  const SheetMoments b = sheetMoments(current.triangles, current.pattern, current.positions);
  double handleMove = 0.0;
  const std::size_t handles = std::min(previous.handleTargets.size(), current.handleTargets.size());
  for (std::size_t h = 0; h < handles; ++h)
    handleMove =
        std::max(handleMove, (current.handleTargets[h] - previous.handleTargets[h]).norm());
  const double jump = std::max((b.centroid - a.centroid).norm(), std::abs(b.gyration - a.gyration));
  return jump / (3.0 * (handleMove + 1e-3));
}

namespace {

// Decoding errors name the cache file.
std::optional<std::vector<cache::ColliderInfo>> readColliders(const cache::CacheReader& reader) {
  try {
    return cache::decodeColliders(reader.header().extensions);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError(reader.path() + ": header: " + e.what());
  }
}

FrameMetrics measure(const cache::CacheReader& reader, const cache::FrameRecord& frame) {
  try {
    return measureFrame(frame);
  } catch (const CorruptDataError& e) {
    throw CorruptDataError(reader.path() + ": " + e.what());
  }
}

}  // namespace

std::string recoveredNote(const cache::CacheReader& reader) {
  if (!reader.recovered()) return {};
  const auto& h = reader.header();
  const long long planned = static_cast<long long>(h.frameEnd) - h.frameStart + 1;
  return reader.path() + " has no footer (a killed or still running shot?): it holds " +
         std::to_string(reader.frameCount()) + " of the " + std::to_string(planned) +
         " planned frames (" + std::to_string(h.frameStart) + "-" + std::to_string(h.frameEnd) +
         ")";
}

std::string inspectJson(const cache::CacheReader& reader) {
  const auto& header = reader.header();
  JsonWriter j;
  j.beginObject();
  j.key("format_version").value(static_cast<long long>(header.formatVersion));
  j.key("fps").value(header.fps);
  j.key("frame_count").value(reader.frameCount());
  // A cache without its footer (a killed run) and the frames its shot planned.
  j.key("recovered").value(reader.recovered());
  j.key("planned_frames").value(static_cast<long long>(header.frameEnd) - header.frameStart + 1);
  const auto colliders = readColliders(reader);
  if (colliders) {
    j.key("colliders").beginArray();
    for (const auto& c : *colliders) {
      j.beginObject();
      j.key("name").value(c.name);
      j.key("material").value(c.material);
      j.key("friction").value(c.friction);
      j.endObject();
    }
    j.endArray();
  }
  j.key("frames").beginArray();
  std::optional<cache::FrameRecord> previous;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    auto frame = reader.readFrame(i);
    auto m = measure(reader, frame);
    if (previous) {
      m.popping = poppingMeasure(*previous, frame);
      if (frame.time > previous->time)
        m.centroidVelocity =
            (m.centroid -
             sheetMoments(previous->triangles, previous->pattern, previous->positions).centroid) /
            (frame.time - previous->time);
    }
    const SelfPenetration self = selfPenetration(frame, header.paperThickness);
    m.selfDepth = self.depth;
    m.selfCrossings = self.crossings;
    j.beginObject();
    j.key("frame").value(m.frame);
    j.key("time").value(m.time);
    j.key("vertices").value(m.vertices);
    j.key("triangles").value(m.triangles);
    j.key("c_mean").value(m.cMean);
    j.key("n_comp").value(m.nComp);
    j.key("max_strain").value(m.maxStrain);
    j.key("max_dihedral").value(m.maxDihedral);
    j.key("handle_error").value(m.handleError);
    j.key("handles").beginArray();
    for (std::size_t h = 0; h < frame.handleTargets.size(); ++h) {
      j.beginObject();
      j.key("name").value(h < header.handleNames.size() ? header.handleNames[h] : std::string());
      const int v = frame.handleVertices[h];
      const Vec3 p = v >= 0 ? frame.positions[static_cast<std::size_t>(v)] : frame.handleTargets[h];
      j.key("position").beginArray().value(p.x()).value(p.y()).value(p.z()).endArray();
      j.endObject();
    }
    j.endArray();
    j.key("singular_vertices").value(m.singularVertices);
    j.key("junction_vertices").value(m.junctionVertices);
    j.key("tears").value(m.tears);
    if (colliders) {
      j.key("contacts").value(m.contacts);
      j.key("max_slide_speed").value(m.maxSlideSpeed);
    }
    j.key("angle_defect_mean").value(m.meanAngleDefect);
    j.key("angle_defect_max").value(m.maxAngleDefect);
    j.key("angle_defect_total").value(m.totalAngleDefect);
    j.key("angle_defect_vertices").value(m.defectVertices);
    j.key("popping").value(m.popping);
    if (m.structure) {
      const cache::StructureChanges& s = *m.structure;
      j.key("structure_changes").beginObject();
      for (const cache::StructureField& field : cache::kStructureFieldList)
        j.key(field.name).value(static_cast<long long>(s.*field.count));
      j.endObject();
    }
    if (header.paperThickness > 0.0) {
      j.key("self_depth").value(m.selfDepth);
      j.key("self_crossings").value(m.selfCrossings);
    }
    const auto vec = [&j](const char* name, const Vec3& a) {
      j.key(name).beginArray().value(a.x()).value(a.y()).value(a.z()).endArray();
    };
    vec("centroid", m.centroid);
    vec("centroid_velocity", m.centroidVelocity);
    vec("mean_normal", m.meanNormal);
    j.key("normal_angle_deg").value(m.normalAngleDeg);
    j.key("extent")
        .beginArray()
        .value(m.extent.x())
        .value(m.extent.y())
        .value(m.extent.z())
        .endArray();
    j.endObject();
    previous = std::move(frame);
  }
  j.endArray();
  j.endObject();
  return j.str() + "\n";
}

std::string inspectText(const cache::CacheReader& reader) {
  const auto& header = reader.header();
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "scene %s, format %u, %.6g fps, %zu frames%s\n",
                header.sceneName.c_str(), header.formatVersion, header.fps, reader.frameCount(),
                reader.recovered() ? " (recovered: no valid footer)" : "");
  out += line;
  for (const auto& issue : reader.issues()) out += "  note: " + issue.message + "\n";
  const auto colliders = readColliders(reader);
  if (colliders) {
    out += "colliders: " + std::to_string(colliders->size()) + "\n";
    for (std::size_t k = 0; k < colliders->size(); ++k) {
      const auto& c = (*colliders)[k];
      std::snprintf(line, sizeof line, ", mu %.6g\n", c.friction);
      out += "  " + std::to_string(k) + ": " + c.name + ", material " + c.material + line;
    }
  }
  std::vector<FrameMetrics> metrics;
  bool torn = false;  // a tears column when any frame has a tear
  std::optional<cache::FrameRecord> previous;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    cache::FrameRecord frame = reader.readFrame(i);
    metrics.push_back(measure(reader, frame));
    if (previous) metrics.back().popping = poppingMeasure(*previous, frame);
    torn = torn || metrics.back().tears > 0;
    previous = std::move(frame);
  }
  std::snprintf(line, sizeof line, "%6s %9s %8s %9s %10s %8s %10s %9s %12s %8s", "frame", "time[s]",
                "verts", "tris", "c_mean", "n_comp", "max_strain", "dihedral", "handle_err[m]",
                "popping");
  out += line;
  if (colliders) {
    std::snprintf(line, sizeof line, " %8s %14s", "contacts", "max_slide[m/s]");
    out += line;
  }
  if (torn) out += "  tears";
  out += "\n";
  for (const FrameMetrics& m : metrics) {
    std::snprintf(line, sizeof line, "%6d %9.4f %8zu %9zu %10.3e %8.4f %10.3e %9.4f %12.3e %8.3f",
                  m.frame, m.time, m.vertices, m.triangles, m.cMean, m.nComp, m.maxStrain,
                  m.maxDihedral, m.handleError, m.popping);
    out += line;
    if (colliders) {
      std::snprintf(line, sizeof line, " %8zu %14.3e", m.contacts, m.maxSlideSpeed);
      out += line;
    }
    if (torn) {
      std::snprintf(line, sizeof line, " %6zu", static_cast<std::size_t>(m.tears));
      out += line;
    }
    out += "\n";
  }
  return out;
}

}  // namespace crumple::pipeline
