#pragma once
// What the sheet touches, as .pcache extension sub-blocks: the
// header block COLL names the colliders, the frame block CONT lists the
// contacts at the end of the frame's last step. The pipeline writes them; the
// sound module reads them. Byte layout in docs/PCACHE.md ("Sub-blocks written
// by crumple"); little-endian like the rest of the cache.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kCollidersTag{'C', 'O', 'L', 'L'};  // header block
inline constexpr std::array<char, 4> kContactsTag{'C', 'O', 'N', 'T'};   // frame block

struct ColliderInfo {
  std::string name;
  std::string material;
  double friction = 0.0;  // Coulomb coefficient mu, finite and >= 0
  bool operator==(const ColliderInfo&) const = default;
};

// ContactRecord::collider: the sheet itself (paper on paper).
inline constexpr int kSelfContact = -1;

struct ContactRecord {
  int vertex = -1;           // vertex of this frame's mesh
  int collider = -1;         // index into the COLL list, or kSelfContact
  float slideSpeed = 0.0f;   // m/s, tangential speed relative to the touched surface
  float normalForce = 0.0f;  // N
  bool operator==(const ContactRecord&) const = default;
};

// The sub-blocks, records in the order given (the producer sorts contacts by
// vertex, then collider). Throw std::invalid_argument for a value the decoder
// would reject (vertex < 0, collider < -1, a negative or non-finite friction,
// speed or force) and std::length_error for more than 2^32 - 1 records.
ExtensionBlock encodeColliders(const std::vector<ColliderInfo>& colliders);  // tag "COLL"
ExtensionBlock encodeContacts(const std::vector<ContactRecord>& contacts);   // tag "CONT"

// Find the block by tag in a header's / frame's extension list and decode it.
// nullopt when no block carries the tag (an older cache, or a scene without
// colliders; a frame without CONT in a cache whose header has COLL touched
// nothing). Throw crumple::CorruptDataError (core/error.hpp, the library's
// error for damaged data) naming the block and the record for malformed data:
// truncated, trailing bytes, a count larger than the block can hold, a second
// block with the same tag, vertex < 0, collider < -1, a negative or non-finite
// friction, slide speed or normal force. Collider indices are not checked
// against the COLL list (the frame decoder does not see it).
std::optional<std::vector<ColliderInfo>> decodeColliders(
    const std::vector<ExtensionBlock>& headerBlocks);
std::optional<std::vector<ContactRecord>> decodeContacts(
    const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
