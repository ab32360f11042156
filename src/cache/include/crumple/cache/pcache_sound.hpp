#pragma once
// A shot's sound events (thesis 4.3.2) as .pcache
// extension sub-blocks, so that a soundtrack can be made again without
// simulating: the header block SNDS says that events were detected and
// with which parameters, the frame block SEVT lists the frame's crumpling,
// friction and tearing events with their resonators. The pipeline writes
// them (crumple simulate); crumple sound reads them. Byte layout in
// docs/PCACHE.md ("Sub-blocks written by crumple"); little-endian like the
// rest of the cache, every real an IEEE binary64.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/types.hpp"
#include "crumple/sound/event_types.hpp"

namespace crumple::cache {

inline constexpr std::array<char, 4> kSoundSetupTag{'S', 'N', 'D', 'S'};   // header block
inline constexpr std::array<char, 4> kSoundEventsTag{'S', 'E', 'V', 'T'};  // frame block

// How the events were detected (sound::EventParams).
struct SoundSetupRecord {
  double gridSpacing = 0.0;         // m
  double curvatureThreshold = 0.0;  // 1/m
  double maxDihedral = 0.0;         // a_max (rad)
  double freeBorderRadius = 0.0;    // m
  double minSlideSpeed = 0.0;       // m/s
  double minFreeBorder = 0.0;       // m
  double maxTearGap = 0.0;          // s
  bool operator==(const SoundSetupRecord&) const = default;
};

// The frame block stores sound::SoundEvent as the sound module defines it
// (crumple/sound/event_types.hpp, header-only).

// Throw std::invalid_argument for a value the decoder would reject: a kind
// above 2, a non-finite value, a negative amplitude, size or radius, or a
// tear below -1, a negative duration; std::length_error for more than 2^32 - 1 records.
ExtensionBlock encodeSoundSetup(const SoundSetupRecord& setup);                  // tag "SNDS"
ExtensionBlock encodeSoundEvents(const std::vector<sound::SoundEvent>& events);  // tag "SEVT"

// nullopt when no block carries the tag (a cache made without [sound]; a
// frame without SEVT in a cache with SNDS had no event). Throw
// crumple::CorruptDataError naming the block and the record for malformed
// data: truncated, trailing bytes, a count larger than the block can hold,
// a second block with the same tag, or a value the encoder refuses.
std::optional<SoundSetupRecord> decodeSoundSetup(const std::vector<ExtensionBlock>& headerBlocks);
std::optional<std::vector<sound::SoundEvent>> decodeSoundEvents(
    const std::vector<ExtensionBlock>& frameBlocks);

}  // namespace crumple::cache
