// libFuzzer target: the cache reader, cache::CacheReader, and the decoders of
// the sub-blocks crumple writes (TEAR, COLL/CONT, SNDS/SEVT, SGEO, SHTR/VELO/PRPV;
// docs/PCACHE.md).
// Any input must either read or throw crumple::InputError (open) or
// crumple::CorruptDataError (a damaged frame or sub-block); everything else
// is a bug. Each input is read twice: as given, and with every chunk's CRC
// recomputed, so that mutations reach the chunk and sub-block decoders
// instead of stopping at the CRC check.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_developable.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"
#include "fuzz_input.hpp"
#include "fuzz_pcache.hpp"

namespace {

void readEverything(const crumple::cache::CacheReader& reader) {
  namespace cache = crumple::cache;
  using crumple::fuzz::tolerateDamage;
  const cache::CacheHeader& header = reader.header();
  tolerateDamage([&] { return cache::decodeColliders(header.extensions); });
  tolerateDamage([&] { return cache::decodeSoundSetup(header.extensions); });
  tolerateDamage([&] { return cache::decodeShutter(header.extensions); });
  (void)reader.verifyAll();
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    (void)reader.frameNumber(i);
    (void)reader.topologySource(i);
    tolerateDamage([&] {
      const cache::FrameRecord frame = reader.readFrame(i);
      tolerateDamage([&] { return cache::decodeTearAtlas(frame.extensions); });
      tolerateDamage([&] { return cache::decodeContacts(frame.extensions); });
      tolerateDamage([&] { return cache::decodeSoundEvents(frame.extensions); });
      tolerateDamage([&] { return cache::decodeDevelopable(frame); });
      tolerateDamage([&] { return cache::decodeVelocities(frame.extensions); });
      tolerateDamage([&] { return cache::decodePropVelocities(frame.extensions); });
      return 0;
    });
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
  crumple::fuzz::asGivenAndWithValidCrcs(data, size, readCache);
  return 0;
}
