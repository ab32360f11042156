// The scene file's [[handles]]: the animated nodes that hold the sheet.
#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "scene_parser.hpp"

namespace crumple::io::detail {

void SceneParser::parseHandles(const TableReader& root) {
  const toml::array* handles = root.tableArray("handles");
  if (!handles) return;
  std::set<std::string> names;
  for (std::size_t i = 0; i < handles->size(); ++i) {
    const TableReader r(*handles->get(i)->as_table(), "handles[" + std::to_string(i) + "]", file_);
    r.allowOnly({"name", "node", "pattern", "tangent_control", "tangent_vertices", "patch_radius",
                 "release_time"});
    HandleSpec h;
    const std::optional<std::string> node = r.string("node");
    if (!node) r.missing("node");
    if (node->empty()) r.fail("node", "must not be empty");
    if (spec_.animationFile.empty()) {
      r.fail("node",
             "handles need an animation file ([scene] animation) holding node '" + *node + "'");
    }
    h.node = *node;
    h.nodeLine = r.lineOf("node");
    h.name = r.string("name").value_or(h.node);
    if (h.name.empty()) r.fail("name", "must not be empty");
    if (!names.insert(h.name).second) {
      r.fail(r.has("name") ? "name" : "node", "duplicate handle name '" + h.name + "'");
    }
    if (auto p = r.vec2("pattern")) {
      const Vec2 q = *p * mpu();
      const SheetSpec& s = spec_.sheet;
      if (s.kind != SheetSpec::Kind::PatternMesh) {  // inside the (bounding) rectangle
        const double tol = 1e-9 * std::max(s.width, s.height);
        if (q.x() < -tol || q.x() > s.width + tol || q.y() < -tol || q.y() > s.height + tol) {
          r.fail("pattern", "point [" + formatNumber((*p).x()) + ", " + formatNumber((*p).y()) +
                                "] is outside the sheet [0, " + formatNumber(s.width / mpu()) +
                                "] x [0, " + formatNumber(s.height / mpu()) + "]");
        }
      }
      h.patternPoint = q;
      h.patternLine = r.lineOf("pattern");
    }
    h.tangentControl = r.boolean("tangent_control").value_or(false);
    if (auto n = r.integer("tangent_vertices")) {
      if (!(*n == 0 || (*n >= 2 && *n <= 4))) {
        r.fail("tangent_vertices",
               "must be 0 (automatic) or 2, 3 or 4 (got " + std::to_string(*n) + ")");
      }
      if (*n != 0 && !h.tangentControl) {
        r.fail("tangent_vertices", "needs tangent_control = true");
      }
      h.tangentVertices = static_cast<int>(*n);
    }
    if (auto radius = r.number("patch_radius")) {
      if (!h.tangentControl) r.fail("patch_radius", "needs tangent_control = true");
      if (h.tangentVertices != 0)
        r.fail("patch_radius", "a handle holds a patch or tangent_vertices, not both");
      const SheetSpec& s = spec_.sheet;
      const double most = 0.25 * std::min(s.width, s.height);
      if (!(*radius > 0.0) || !(*radius * mpu() <= most))
        r.fail("patch_radius", "must be above 0 and at most a quarter of the sheet's side (" +
                                   formatNumber(most / mpu()) + "; got " + formatNumber(*radius) +
                                   ")");
      h.patchRadius = *radius * mpu();
    }
    if (auto t = r.number("release_time")) {
      h.releaseTime = r.requireNonNegative("release_time", *t);
    }
    spec_.handles.push_back(std::move(h));
  }
}

}  // namespace crumple::io::detail
