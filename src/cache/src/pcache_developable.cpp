// The SGEO extension sub-block. Byte layout: docs/PCACHE.md ("Sub-blocks
// written by crumple").
#include "crumple/cache/pcache_developable.hpp"

#include <string>
#include <utility>

#include "crumple/core/index.hpp"
#include "sub_block.hpp"

namespace crumple::cache {

ExtensionBlock encodeRegionRulings(const std::vector<RegionRulings>& regions) {
  Bytes bytes;
  ByteWriter w(bytes);
  detail::writeRecords(
      w, regions, "encodeRegionRulings", "region",
      [](const RegionRulings& r) { return r.region < 0 || r.apex < -1 ? "negative id" : ""; },
      [&](const RegionRulings& r) {
        w.i32(r.region);
        w.i32(r.apex);
        w.u32(r.count);
      });
  return {kDevelopableTag, std::move(bytes)};
}

std::optional<mesh::DevelopableStructure> decodeDevelopable(const FrameRecord& frame) {
  const auto regions = detail::decodeBlock(frame.extensions, kDevelopableTag, [](auto& r) {
    return detail::readRecords<RegionRulings>(r, 12, "region", [&](RegionRulings& x) {
      x.region = r.i32("region");
      x.apex = r.i32("apex");
      x.count = r.u32("ruling count");
    });
  });
  if (!regions) return std::nullopt;
  const auto fail = [&](std::size_t i, const std::string& problem) {
    return CorruptDataError("frame " + std::to_string(frame.frame) +
                            ": pcache SGEO sub-block: region " + std::to_string(i) + ": " +
                            problem);
  };
  mesh::DevelopableStructure out;
  std::size_t next = 0;
  for (std::size_t i = 0; i < regions->size(); ++i) {
    const RegionRulings& r = (*regions)[i];
    if (!inRange(frame.regionTypes, r.region)) throw fail(i, "region id out of range");
    if (r.apex < -1 || r.apex >= std::ssize(frame.positions)) throw fail(i, "apex out of range");
    if (r.count > frame.rulings.size() - next)
      throw fail(i, "more rulings than the frame's ruling list holds");
    mesh::CurvedRegion region;
    region.region = r.region;
    region.apex = r.apex;
    region.rulings.assign(frame.rulings.begin() + static_cast<std::ptrdiff_t>(next),
                          frame.rulings.begin() + static_cast<std::ptrdiff_t>(next + r.count));
    next += r.count;
    if (frame.regionTypes[idx(r.region)] == static_cast<std::uint8_t>(mesh::RegionType::Curved) &&
        region.rulings.size() >= 2)
      out.regions.push_back(std::move(region));
  }
  if (next != frame.rulings.size())
    throw CorruptDataError("frame " + std::to_string(frame.frame) +
                           ": pcache SGEO sub-block: its regions hold " + std::to_string(next) +
                           " of the frame's " + std::to_string(frame.rulings.size()) + " rulings");
  return out;
}

}  // namespace crumple::cache
