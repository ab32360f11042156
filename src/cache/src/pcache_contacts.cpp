// The COLL and CONT extension sub-blocks. Byte layout: docs/PCACHE.md
// ("Sub-blocks written by crumple").
#include "crumple/cache/pcache_contacts.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "crumple/core/error.hpp"
#include "sub_block.hpp"

namespace crumple::cache {
namespace {

static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4,
              "floats are stored as IEEE-754 binary32");
static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8,
              "doubles are stored as IEEE-754 binary64");
static_assert(sizeof(int) == 4, "ints are stored as 32-bit two's complement");

// Smallest encoded record: a collider with two empty strings (2 u32 + f64),
// a contact (2 i32 + 2 f32).
constexpr std::size_t kMinColliderBytes = 4 + 4 + 8;
constexpr std::size_t kContactBytes = 4 + 4 + 4 + 4;

using detail::decodeBlock;
using detail::readRecords;
using detail::writeRecords;
using Reader = detail::SubBlockReader;

bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

std::string valueText(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// The problem with a contact, or empty when it is valid.
std::string contactProblem(const ContactRecord& c) {
  if (c.vertex < 0) return "vertex " + std::to_string(c.vertex) + " is negative";
  if (c.collider < kSelfContact)
    return "collider " + std::to_string(c.collider) + " is neither an index nor -1 (self contact)";
  if (!finiteNonNegative(c.slideSpeed))
    return "slide speed " + valueText(c.slideSpeed) + " is not a finite non-negative number";
  if (!finiteNonNegative(c.normalForce))
    return "normal force " + valueText(c.normalForce) + " is not a finite non-negative number";
  return {};
}

std::string frictionProblem(double friction) {
  if (!finiteNonNegative(friction))
    return "friction " + valueText(friction) + " is not a finite non-negative number";
  return {};
}

}  // namespace

ExtensionBlock encodeColliders(const std::vector<ColliderInfo>& colliders) {
  Bytes bytes;
  ByteWriter w(bytes);
  const auto problem = [](const ColliderInfo& c) {
    const std::string p = frictionProblem(c.friction);
    return p.empty() ? p : "'" + c.name + "': " + p;
  };
  writeRecords(w, colliders, "encodeColliders", "collider", problem, [&](const ColliderInfo& c) {
    w.str32(c.name, "bytes in a collider name");
    w.str32(c.material, "bytes in a collider material");
    w.f64(c.friction);
  });
  return {kCollidersTag, std::move(bytes)};
}

ExtensionBlock encodeContacts(const std::vector<ContactRecord>& contacts) {
  Bytes bytes;
  ByteWriter w(bytes);
  writeRecords(w, contacts, "encodeContacts", "contact", contactProblem,
               [&](const ContactRecord& c) {
                 w.i32(c.vertex);
                 w.i32(c.collider);
                 w.f32(c.slideSpeed);
                 w.f32(c.normalForce);
               });
  return {kContactsTag, std::move(bytes)};
}

std::optional<std::vector<ColliderInfo>> decodeColliders(
    const std::vector<ExtensionBlock>& headerBlocks) {
  return decodeBlock(headerBlocks, kCollidersTag, [](Reader& r) {
    return readRecords<ColliderInfo>(r, kMinColliderBytes, "collider", [&](ColliderInfo& c) {
      c.name = r.str32("name");
      c.material = r.str32("material");
      c.friction = r.f64("friction");
      if (const auto problem = frictionProblem(c.friction); !problem.empty()) r.fail(problem);
    });
  });
}

std::optional<std::vector<ContactRecord>> decodeContacts(
    const std::vector<ExtensionBlock>& frameBlocks) {
  return decodeBlock(frameBlocks, kContactsTag, [](Reader& r) {
    return readRecords<ContactRecord>(r, kContactBytes, "contact", [&](ContactRecord& c) {
      c.vertex = r.i32("vertex");
      c.collider = r.i32("collider");
      c.slideSpeed = r.f32("slide speed");
      c.normalForce = r.f32("normal force");
      if (const auto problem = contactProblem(c); !problem.empty()) r.fail(problem);
    });
  });
}

}  // namespace crumple::cache
