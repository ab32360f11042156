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

// Reads a block; errors name the block, the record being read (at()) and
// the field. Messages are built only on failure.
class Reader {
 public:
  Reader(const Bytes& bytes, const char* block) : bytes_(bytes), block_(block) {}

  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(get(4, what)); }
  int i32(const char* what) { return static_cast<std::int32_t>(u32(what)); }
  float f32(const char* what) { return std::bit_cast<float>(u32(what)); }
  double f64(const char* what) { return std::bit_cast<double>(get(8, what)); }
  // A u32 count of records of at least `minBytes` each, checked against what
  // is left so that a damaged count cannot trigger a huge allocation.
  std::size_t count(std::size_t minBytes, const char* what) {
    const std::size_t n = u32(what);
    if (n > remaining() / minBytes)
      fail(std::string(what) + " " + std::to_string(n) + " runs past the end of the block (" +
           std::to_string(remaining()) + " bytes left)");
    return n;
  }
  std::string str(const char* what) {
    const std::size_t n = u32(what);
    if (n > remaining())
      fail(std::string(what) + ": length " + std::to_string(n) + " runs past the end of the block");
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  // The record the next reads belong to, for messages.
  void at(const char* kind, std::size_t index) {
    kind_ = kind;
    index_ = index;
  }
  void expectEnd() {
    kind_ = nullptr;
    if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
  }
  [[noreturn]] void fail(const std::string& problem) const {
    std::string where = kind_ ? std::string(kind_) + " " + std::to_string(index_) + ": " : "";
    throw CorruptDataError(std::string("pcache ") + block_ + " sub-block: " + where + problem);
  }

 private:
  std::size_t remaining() const { return bytes_.size() - pos_; }
  std::uint64_t get(int n, const char* what) {
    if (static_cast<std::size_t>(n) > remaining()) fail(std::string(what) + " truncated");
    std::uint64_t v = 0;
    for (int k = 0; k < n; ++k) v |= static_cast<std::uint64_t>(bytes_[pos_ + k]) << (8 * k);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  const Bytes& bytes_;
  const char* block_;
  const char* kind_ = nullptr;
  std::size_t index_ = 0;
  std::size_t pos_ = 0;
};

bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

std::string valueText(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string tagName(const std::array<char, 4>& tag) { return std::string(tag.data(), tag.size()); }

// The one block with `tag`, or null; two are malformed.
const ExtensionBlock* findOne(const std::vector<ExtensionBlock>& blocks,
                              const std::array<char, 4>& tag) {
  const ExtensionBlock* found = nullptr;
  for (const auto& b : blocks) {
    if (b.tag != tag) continue;
    if (found)
      throw CorruptDataError("pcache " + tagName(tag) + " sub-block: present more than once");
    found = &b;
  }
  return found;
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
  const ExtensionBlock* block = findOne(headerBlocks, kCollidersTag);
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
  const ExtensionBlock* block = findOne(frameBlocks, kContactsTag);
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
