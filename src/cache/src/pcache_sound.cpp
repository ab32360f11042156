// The SNDS and SEVT extension sub-blocks. Byte layout: docs/PCACHE.md
// ("Sub-blocks written by crumple").
#include "crumple/cache/pcache_sound.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "sub_block.hpp"

namespace crumple::cache {
namespace {

using detail::decodeBlock;
using detail::readRecords;
using detail::writeRecords;
using Reader = detail::SubBlockReader;

constexpr std::size_t kSetupBytes = 7 * 8;
constexpr std::size_t kResonatorBytes = 10 * 8;
constexpr std::size_t kMinEventBytes = 1 + 4 + 8 * 8 + 4;

bool finite(const Vec3& v) { return v.allFinite(); }
bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

std::string setupProblem(const SoundSetupRecord& s) {
  if (!(std::isfinite(s.gridSpacing) && s.gridSpacing > 0.0)) return "grid spacing is not positive";
  if (!(std::isfinite(s.curvatureThreshold) && s.curvatureThreshold > 0.0))
    return "curvature threshold is not positive";
  if (!(std::isfinite(s.maxDihedral) && s.maxDihedral > 0.0)) return "a_max is not positive";
  if (!(std::isfinite(s.freeBorderRadius) && s.freeBorderRadius > 0.0))
    return "free border radius is not positive";
  if (!finiteNonNegative(s.minSlideSpeed)) return "minimum slide speed is negative";
  if (!finiteNonNegative(s.minFreeBorder)) return "shortest free border is negative";
  if (!(std::isfinite(s.maxTearGap) && s.maxTearGap > 0.0))
    return "longest tear gap is not positive";
  return {};
}

std::string resonatorProblem(const sound::Resonator& r) {
  if (!finiteNonNegative(r.ruling) || !finiteNonNegative(r.border) || !finiteNonNegative(r.area) ||
      !finiteNonNegative(r.radius))
    return "a size (l_r, l_c, area, radius) is negative or not finite";
  if (!finite(r.centre) || !finite(r.normal)) return "a non-finite centre or normal";
  return {};
}

std::string eventProblem(const sound::SoundEvent& e) {
  const auto kind = static_cast<unsigned>(e.kind);
  if (kind > 2) return "kind " + std::to_string(kind) + " is not 0, 1 or 2";
  if (e.tear < -1) return "tear " + std::to_string(e.tear) + " is below -1";
  if (!finiteNonNegative(e.amplitude)) return "amplitude is negative or not finite";
  if (!finiteNonNegative(e.duration)) return "duration is negative or not finite";
  if (!finite(e.position) || !finite(e.normal)) return "a non-finite position or normal";
  for (std::size_t k = 0; k < e.resonators.size(); ++k)
    if (const auto problem = resonatorProblem(e.resonators[k]); !problem.empty())
      return "resonator " + std::to_string(k) + ": " + problem;
  return {};
}

void vec3(ByteWriter& w, const Vec3& v) {
  for (int k = 0; k < 3; ++k) w.f64(v[k]);
}
Vec3 vec3(Reader& r, const char* what) {
  Vec3 v;
  for (int k = 0; k < 3; ++k) v[k] = r.f64(what);
  return v;
}

}  // namespace

ExtensionBlock encodeSoundSetup(const SoundSetupRecord& s) {
  if (const auto problem = setupProblem(s); !problem.empty())
    throw std::invalid_argument("encodeSoundSetup: " + problem);
  Bytes bytes;
  ByteWriter w(bytes);
  w.f64(s.gridSpacing);
  w.f64(s.curvatureThreshold);
  w.f64(s.maxDihedral);
  w.f64(s.freeBorderRadius);
  w.f64(s.minSlideSpeed);
  w.f64(s.minFreeBorder);
  w.f64(s.maxTearGap);
  return {kSoundSetupTag, std::move(bytes)};
}

ExtensionBlock encodeSoundEvents(const std::vector<sound::SoundEvent>& events) {
  Bytes bytes;
  ByteWriter w(bytes);
  writeRecords(w, events, "encodeSoundEvents", "event", eventProblem,
               [&](const sound::SoundEvent& e) {
                 w.u8(static_cast<std::uint8_t>(e.kind));
                 w.i32(e.tear);
                 w.f64(e.amplitude);
                 w.f64(e.duration);
                 vec3(w, e.position);
                 vec3(w, e.normal);
                 // Checked with their event (eventProblem), which names both.
                 const auto checked = [](const sound::Resonator&) { return std::string(); };
                 writeRecords(w, e.resonators, "encodeSoundEvents", "resonator", checked,
                              [&](const sound::Resonator& r) {
                                w.f64(r.ruling);
                                w.f64(r.border);
                                w.f64(r.area);
                                vec3(w, r.centre);
                                vec3(w, r.normal);
                                w.f64(r.radius);
                              });
               });
  return {kSoundEventsTag, std::move(bytes)};
}

std::optional<SoundSetupRecord> decodeSoundSetup(const std::vector<ExtensionBlock>& headerBlocks) {
  return decodeBlock(headerBlocks, kSoundSetupTag, [](Reader& r) {
    if (r.remaining() < kSetupBytes) r.fail("truncated");
    SoundSetupRecord s;
    s.gridSpacing = r.f64("grid spacing");
    s.curvatureThreshold = r.f64("curvature threshold");
    s.maxDihedral = r.f64("a_max");
    s.freeBorderRadius = r.f64("free border radius");
    s.minSlideSpeed = r.f64("minimum slide speed");
    s.minFreeBorder = r.f64("shortest free border");
    s.maxTearGap = r.f64("longest tear gap");
    if (const auto problem = setupProblem(s); !problem.empty()) r.fail(problem);
    return s;
  });
}

std::optional<std::vector<sound::SoundEvent>> decodeSoundEvents(
    const std::vector<ExtensionBlock>& frameBlocks) {
  return decodeBlock(frameBlocks, kSoundEventsTag, [](Reader& r) {
    return readRecords<sound::SoundEvent>(r, kMinEventBytes, "event", [&](sound::SoundEvent& e) {
      e.kind = static_cast<sound::EventKind>(r.u8("kind"));  // checked below
      e.tear = r.i32("tear");
      e.amplitude = r.f64("amplitude");
      e.duration = r.f64("duration");
      e.position = vec3(r, "position");
      e.normal = vec3(r, "normal");
      if (const auto problem = eventProblem(e); !problem.empty()) r.fail(problem);
      e.resonators.resize(r.count32(kResonatorBytes, "resonator count"));
      for (auto& q : e.resonators) {
        q.ruling = r.f64("l_r");
        q.border = r.f64("l_c");
        q.area = r.f64("area");
        q.centre = vec3(r, "centre");
        q.normal = vec3(r, "normal");
        q.radius = r.f64("radius");
        if (const auto problem = resonatorProblem(q); !problem.empty()) r.fail(problem);
      }
    });
  });
}

}  // namespace crumple::cache
