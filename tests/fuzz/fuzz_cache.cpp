// libFuzzer target: the cache reader, cache::CacheReader, and the decoders of
// the sub-blocks crumple writes (TEAR, COLL/CONT, SNDS/SEVT; docs/PCACHE.md).
// Any input must either read or throw crumple::InputError (open) or
// crumple::CorruptDataError (a damaged frame or sub-block); everything else
// is a bug. Each input is read twice: as given, and with every chunk's CRC
// recomputed, so that mutations reach the chunk and sub-block decoders
// instead of stopping at the CRC check.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/pcache.hpp"
#include "crumple/exporters/pcache_contacts.hpp"
#include "crumple/exporters/pcache_sound.hpp"
#include "crumple/exporters/pcache_tear.hpp"
#include "fuzz_input.hpp"
#include "fuzz_pcache.hpp"

namespace {

void readEverything(const crumple::cache::CacheReader& reader) {
  namespace cache = crumple::cache;
  const cache::CacheHeader& header = reader.header();
  try {
    (void)cache::decodeColliders(header.extensions);
  } catch (const crumple::CorruptDataError&) {
  }
  try {
    (void)cache::decodeSoundSetup(header.extensions);
  } catch (const crumple::CorruptDataError&) {
  }
  (void)reader.verifyAll();
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    (void)reader.frameNumber(i);
    (void)reader.topologySource(i);
    try {
      const cache::FrameRecord frame = reader.readFrame(i);
      try {
        (void)cache::decodeTearAtlas(frame.extensions);
      } catch (const crumple::CorruptDataError&) {
      }
      try {
        (void)cache::decodeContacts(frame.extensions);
      } catch (const crumple::CorruptDataError&) {
      }
      try {
        (void)cache::decodeSoundEvents(frame.extensions);
      } catch (const crumple::CorruptDataError&) {
      }
    } catch (const crumple::CorruptDataError&) {
    }
  }
}

void readCache(const std::uint8_t* data, std::size_t size) {
  const std::string& path = crumple::fuzz::writeScratch(".pcache", data, size);
  try {
    const crumple::cache::CacheReader reader(path);
    readEverything(reader);
  } catch (const crumple::InputError&) {
    // A missing or damaged header: the intended behaviour.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  readCache(data, size);
  const std::vector<std::uint8_t> fixed = crumple::fuzz::withValidCrcs(data, size);
  if (!std::equal(fixed.begin(), fixed.end(), data)) readCache(fixed.data(), fixed.size());
  return 0;
}
