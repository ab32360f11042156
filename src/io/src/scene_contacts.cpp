// The scene file's contacts: [friction] (Coulomb coefficients by material),
// [[colliders]] and [contact] (self-contact).
#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scene_parser.hpp"

namespace crumple::io::detail {

namespace {

// Coulomb coefficient of the built-in [friction] entries "default" and "paper".
constexpr double kDefaultFriction = 0.3;

// A [friction] material name: non-empty, only a-z, 0-9, _ and -.
bool isMaterialName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '-';
  });
}

std::string notMaterialName(const std::string& name) {
  return "'" + name + "' is not a material name (use only a-z, 0-9, _ and -)";
}

}  // namespace

// [friction]: material name = Coulomb coefficient of paper on it, on top of
// the built-in default and paper (paper on paper).
void SceneParser::parseFriction(const toml::table* table) {
  spec_.friction = {{"default", kDefaultFriction}, {"paper", kDefaultFriction}};
  if (!table) return;
  const TableReader r(*table, "friction", file_);
  // Report the first bad entry in file order (toml++ sorts keys).
  std::vector<std::pair<long, std::string>> keys;
  for (auto&& [k, v] : *table)
    keys.emplace_back(static_cast<long>(k.source().begin.line), std::string(k.str()));
  std::sort(keys.begin(), keys.end());
  for (const auto& [line, name] : keys) {
    if (!isMaterialName(name)) r.fail(name, notMaterialName(name));
    spec_.friction[name] = r.requireNonNegative(name, *r.number(name));
  }
}

void SceneParser::parseColliders(const TableReader& root) {
  const toml::array* colliders = root.tableArray("colliders");
  if (!colliders) return;
  std::set<std::string> names;
  for (std::size_t i = 0; i < colliders->size(); ++i) {
    const TableReader r(*colliders->get(i)->as_table(), "colliders[" + std::to_string(i) + "]",
                        file_);
    r.allowOnly(
        {"name", "type", "position", "normal", "size", "radius", "node", "material", "friction"});
    ColliderSpec c;
    const std::optional<std::string> type = r.string("type");
    if (!type) r.missing("type");
    const auto only = [&](const char* key, const char* types) {
      if (r.has(key)) r.fail(key, std::string("only for ") + types);
    };
    // A box or sphere may follow any node (position is then its offset).
    const auto followNode = [&](const std::string& what) {
      const std::optional<std::string> node = r.string("node");
      if (!node) return;
      if (node->empty()) r.fail("node", "must not be empty");
      if (spec_.animationFile.empty()) {
        r.fail("node",
               "a " + what + " following a node needs an animation file ([scene] animation)");
      }
      c.node = *node;
      c.nodeLine = r.lineOf("node");
    };
    if (auto p = r.vec3("position")) c.position = *p * mpu();
    if (*type == "plane") {
      c.kind = ColliderSpec::Kind::Plane;
      if (auto n = r.vec3("normal")) c.normal = r.requireDirection("normal", *n);
      only("size", "boxes");
      only("radius", "spheres");
      only("node", "meshes, boxes and spheres");
    } else if (*type == "box") {
      c.kind = ColliderSpec::Kind::Box;
      const std::optional<Vec3> sz = r.vec3("size");
      if (!sz) r.missing("size");
      if (!(sz->minCoeff() > 0.0)) r.fail("size", "every side must be > 0");
      c.size = *sz * mpu();
      only("normal", "planes");
      only("radius", "spheres");
      followNode("box");
    } else if (*type == "sphere") {
      c.kind = ColliderSpec::Kind::Sphere;
      const std::optional<double> rad = r.number("radius");
      if (!rad) r.missing("radius");
      c.radius = r.requirePositive("radius", *rad) * mpu();
      only("normal", "planes");
      only("size", "boxes");
      followNode("sphere");
    } else if (*type == "mesh") {
      c.kind = ColliderSpec::Kind::Mesh;
      const std::optional<std::string> node = r.string("node");
      if (!node) r.missing("node");
      if (node->empty()) r.fail("node", "must not be empty");
      if (spec_.animationFile.empty())
        r.fail("node", "a mesh collider needs an animation file ([scene] animation)");
      c.node = *node;
      c.nodeLine = r.lineOf("node");
      only("position", "planes, boxes and spheres (a mesh moves with its node)");
      only("normal", "planes");
      only("size", "boxes");
      only("radius", "spheres");
    } else {
      r.fail("type", "unknown collider type '" + *type + "' (expected plane, box, sphere or mesh)");
    }
    // Friction: an explicit `friction` wins, else the material's [friction]
    // entry, else [friction] default.
    const std::optional<std::string> material = r.string("material");
    if (material && !isMaterialName(*material)) r.fail("material", notMaterialName(*material));
    if (auto mu = r.number("friction")) {
      c.friction = r.requireNonNegative("friction", *mu);
      c.material = material.value_or("custom");
    } else if (material) {
      const auto it = spec_.friction.find(*material);
      if (it == spec_.friction.end()) {
        std::string known;
        for (const auto& entry : spec_.friction) known += (known.empty() ? "" : ", ") + entry.first;
        r.fail("material", "material '" + *material +
                               "' has no coefficient: add it to [friction] (known: " + known + ")");
      }
      c.friction = it->second;
      c.material = *material;
    } else {
      c.friction = spec_.friction.at("default");
      c.material = "default";
    }
    c.name = r.string("name").value_or(c.node.empty() ? "collider" + std::to_string(i) : c.node);
    if (c.name.empty()) r.fail("name", "must not be empty");
    if (!names.insert(c.name).second) r.fail("name", "duplicate collider name '" + c.name + "'");
    spec_.colliders.push_back(std::move(c));
  }
}

// [contact] self = true | false | "auto".
void SceneParser::parseContact(const toml::table* table) {
  if (!table) return;
  const TableReader r(*table, "contact", file_);
  r.allowOnly({"self"});
  const toml::node* self = r.find("self");
  if (!self) return;
  const std::string expected = "expected true, false or \"auto\"";
  if (auto b = self->as_boolean()) {
    spec_.contact.self = b->get() ? ContactSpec::Self::On : ContactSpec::Self::Off;
  } else if (auto str = self->as_string()) {
    if (str->get() != "auto") r.fail("self", expected + " (got \"" + str->get() + "\")");
    spec_.contact.self = ContactSpec::Self::Auto;
  } else {
    r.fail("self", expected + ", got " + detail::typeName(*self));
  }
}

}  // namespace crumple::io::detail
