#include "aov_pass.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "integrator.hpp"

namespace crumple::render::pt {

std::vector<std::uint8_t> sheetTriangleRegions(const mesh::SheetMesh& sheet, bool modelled) {
  std::vector<std::uint8_t> out(sheet.triangles.size(), 0);
  if (!modelled || sheet.regionTypes.empty() ||
      sheet.regionOfTriangle.size() != sheet.triangles.size())
    return out;
  for (std::size_t t = 0; t < out.size(); ++t) {
    const int region = sheet.regionOfTriangle[t];
    const bool curved =
        region >= 0 && static_cast<std::size_t>(region) < sheet.regionTypes.size() &&
        sheet.regionTypes[static_cast<std::size_t>(region)] == mesh::RegionType::Curved;
    out[t] = curved ? 2 : 1;
  }
  return out;
}

std::vector<std::uint8_t> singularCorners(const mesh::SheetMesh& sheet,
                                          const std::vector<int>& sharpVertices) {
  std::vector<bool> sharp(sheet.vertexCount(), false);
  for (const int v : sharpVertices)
    if (v >= 0 && static_cast<std::size_t>(v) < sharp.size())
      sharp[static_cast<std::size_t>(v)] = true;
  std::vector<std::uint8_t> out(sheet.triangles.size(), 0);
  for (std::size_t t = 0; t < out.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k)
      if (sharp[static_cast<std::size_t>(sheet.triangles[t][k])])
        out[t] |= static_cast<std::uint8_t>(1u << k);
  return out;
}

std::vector<std::uint16_t> nearestHandles(const mesh::SheetMesh& sheet,
                                          const std::vector<int>& handleVertices) {
  std::vector<std::uint16_t> out(sheet.triangles.size(), 0);
  for (std::size_t t = 0; t < out.size(); ++t) {
    const auto& tri = sheet.triangles[t];
    const Vec2 c = (sheet.pattern[static_cast<std::size_t>(tri[0])] +
                    sheet.pattern[static_cast<std::size_t>(tri[1])] +
                    sheet.pattern[static_cast<std::size_t>(tri[2])]) /
                   3.0;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t h = 0; h < handleVertices.size() && h < 0xFFFF; ++h) {
      const int v = handleVertices[h];
      if (v < 0 || static_cast<std::size_t>(v) >= sheet.vertexCount()) continue;
      const double d = (sheet.pattern[static_cast<std::size_t>(v)] - c).squaredNorm();
      if (d < best) {
        best = d;
        out[t] = static_cast<std::uint16_t>(h + 1);
      }
    }
  }
  return out;
}

AovImage makeAovImage(const std::vector<Aov>& aovs, int width, int height) {
  AovImage out;
  out.width = width;
  out.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (const Aov aov : aovs)
    for (std::string& name : aovChannelNames(aov)) {
      ImageChannel& c = out.channels.emplace_back();
      c.name = std::move(name);
      c.fullFloat =
          aov == Aov::Depth || aov == Aov::Position || aov == Aov::HandleId || aov == Aov::ObjectId;
      c.pixels.assign(n, aov == Aov::Depth ? kAovFarDepth : 0.0f);
    }
  return out;
}

void AovPixel::reset() {
  hits_ = 0;
  nearest_ = kAovFarDepth;
  std::fill(std::begin(normal_), std::end(normal_), 0.0);
  std::fill(std::begin(albedo_), std::end(albedo_), 0.0);
  std::fill(std::begin(position_), std::end(position_), 0.0);
  std::fill(std::begin(region_), std::end(region_), 0);
  objects_.clear();
  handles_.clear();
}

void AovPixel::count(std::vector<std::pair<float, int>>& counts, float id) {
  for (auto& [key, n] : counts)
    if (key == id) {
      ++n;
      return;
    }
  counts.emplace_back(id, 1);
}

float AovPixel::majority(const std::vector<std::pair<float, int>>& counts) {
  float id = 0.0f;
  int most = 0;
  for (const auto& [key, n] : counts)
    if (n > most || (n == most && key < id)) {
      id = key;
      most = n;
    }
  return id;
}

void AovPixel::add(const RTCRayHit& rh, const Surface& s) {
  const MeshData& m = f_.meshes[rh.hit.geomID];
  ++hits_;
  nearest_ = std::min(nearest_, dot(s.p - f_.camera.pos, f_.camera.forward));
  const V3 n = s.ns, a = s.albedo, p = s.p;
  const float nv[3] = {n.x, n.y, n.z}, av[3] = {a.x, a.y, a.z}, pv[3] = {p.x, p.y, p.z};
  for (int k = 0; k < 3; ++k) {
    normal_[k] += nv[k];
    albedo_[k] += av[k];
    position_[k] += pv[k];
  }
  count(objects_, m.objectId);
  if (m.kind == GeomKind::Sheet) {
    const TriangleHit h = triangleHit(m, rh.hit.primID, rh.hit.u, rh.hit.v);
    const SheetTri& t = f_.sheet.tris[h.triangle];
    const float weights[3] = {1.0f - h.u - h.v, h.u, h.v};
    bool singular = false;
    for (int k = 0; k < 3; ++k)
      singular |= (t.singularCorners >> k & 1u) != 0 && weights[k] >= kSingularNeighbourhood;
    if (t.region > 0) ++region_[singular ? 2 : t.region - 1];
    count(handles_, static_cast<float>(t.handle));
  }
}

void AovPixel::store(const std::vector<Aov>& aovs, std::size_t pixel, int spp,
                     AovImage& out) const {
  std::size_t c = 0;
  const auto put = [&](double value) {
    out.channels[c++].pixels[pixel] = static_cast<float>(value);
  };
  const double invSpp = 1.0 / spp, invHits = hits_ > 0 ? 1.0 / hits_ : 0.0;
  for (const Aov aov : aovs) switch (aov) {
      case Aov::Depth:
        put(nearest_);
        break;
      case Aov::Normal: {
        const double len =
            std::sqrt(normal_[0] * normal_[0] + normal_[1] * normal_[1] + normal_[2] * normal_[2]);
        for (const double v : normal_) put(len > 0.0 ? v / len : 0.0);
        break;
      }
      case Aov::Albedo:
        for (const double v : albedo_) put(v * invSpp);
        break;
      case Aov::Position:
        for (int k = 0; k < 3; ++k) put(hits_ > 0 ? f_.origin(k) + position_[k] * invHits : 0.0);
        break;
      case Aov::Region:
        for (const int v : region_) put(v * invSpp);
        break;
      case Aov::HandleId:
        put(majority(handles_));
        break;
      case Aov::ObjectId:
        put(majority(objects_));
        break;
    }
}

}  // namespace crumple::render::pt
