// The COLL and CONT extension sub-blocks. Byte layout: docs/PCACHE.md
// ("Sub-blocks written by crumple").
#include "crumple/exporters/pcache_contacts.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "block_reader.hpp"
#include "byte_encoder.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4,
              "floats are stored as IEEE-754 binary32");
static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8,
              "doubles are stored as IEEE-754 binary64");
static_assert(sizeof(int) == 4, "ints are stored as 32-bit two's complement");

using detail::Bytes;
using detail::Encoder;

// Smallest encoded record: a collider with two empty strings (2 u32 + f64),
// a contact (2 i32 + 2 f32).
constexpr std::size_t kMinColliderBytes = 4 + 4 + 8;
constexpr std::size_t kContactBytes = 4 + 4 + 4 + 4;

using detail::findOneBlock;
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
  Encoder w(bytes);
  w.count(colliders.size(), "colliders");
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    const auto& c = colliders[i];
    if (const auto problem = frictionProblem(c.friction); !problem.empty())
      throw std::invalid_argument("encodeColliders: collider " + std::to_string(i) + " ('" +
                                  c.name + "'): " + problem);
    w.str(c.name, "bytes in a collider name");
    w.str(c.material, "bytes in a collider material");
    w.f64(c.friction);
  }
  return {kCollidersTag, std::move(bytes)};
}

ExtensionBlock encodeContacts(const std::vector<ContactRecord>& contacts) {
  Bytes bytes;
  Encoder w(bytes);
  w.count(contacts.size(), "contacts");
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto& c = contacts[i];
    if (const auto problem = contactProblem(c); !problem.empty())
      throw std::invalid_argument("encodeContacts: contact " + std::to_string(i) + ": " + problem);
    w.i32(c.vertex);
    w.i32(c.collider);
    w.f32(c.slideSpeed);
    w.f32(c.normalForce);
  }
  return {kContactsTag, std::move(bytes)};
}

std::optional<std::vector<ColliderInfo>> decodeColliders(
    const std::vector<ExtensionBlock>& headerBlocks) {
  const ExtensionBlock* block = findOneBlock(headerBlocks, kCollidersTag);
  if (!block) return std::nullopt;
  Reader r(block->data, "COLL");
  std::vector<ColliderInfo> colliders(r.count(kMinColliderBytes, "collider count"));
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    auto& c = colliders[i];
    r.at("collider", i);
    c.name = r.str("name");
    c.material = r.str("material");
    c.friction = r.f64("friction");
    if (const auto problem = frictionProblem(c.friction); !problem.empty()) r.fail(problem);
  }
  r.expectEnd();
  return colliders;
}

std::optional<std::vector<ContactRecord>> decodeContacts(
    const std::vector<ExtensionBlock>& frameBlocks) {
  const ExtensionBlock* block = findOneBlock(frameBlocks, kContactsTag);
  if (!block) return std::nullopt;
  Reader r(block->data, "CONT");
  std::vector<ContactRecord> contacts(r.count(kContactBytes, "contact count"));
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    auto& c = contacts[i];
    r.at("contact", i);
    c.vertex = r.i32("vertex");
    c.collider = r.i32("collider");
    c.slideSpeed = r.f32("slide speed");
    c.normalForce = r.f32("normal force");
    if (const auto problem = contactProblem(c); !problem.empty()) r.fail(problem);
  }
  r.expectEnd();
  return contacts;
}

}  // namespace crumple::cache
