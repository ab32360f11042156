// The motion sub-blocks SHTR, VELO, PRPV. Byte layout: docs/PCACHE.md.
#include "crumple/cache/pcache_motion.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "sub_block.hpp"

namespace crumple::cache {

using detail::decodeBlock;
using detail::readRecords;
using detail::SubBlockReader;
using detail::writeRecords;

namespace {

bool validShutter(const Shutter& s) {
  return std::isfinite(s.open) && std::isfinite(s.close) && s.open >= -1.0 && s.close <= 1.0 &&
         s.open < s.close;
}

bool validVelocity(const Vec3& v) { return v.allFinite() && v.cwiseAbs().maxCoeff() <= kMaxSpeed; }

}  // namespace

ExtensionBlock encodeShutter(const Shutter& shutter) {
  if (!validShutter(shutter))
    throw std::invalid_argument("encodeShutter: not an open shutter within [-1, 1] frames");
  Bytes bytes;
  ByteWriter w(bytes);
  w.f64(shutter.open);
  w.f64(shutter.close);
  return {kShutterTag, std::move(bytes)};
}

std::optional<Shutter> decodeShutter(const std::vector<ExtensionBlock>& headerBlocks) {
  return decodeBlock(headerBlocks, kShutterTag, [](SubBlockReader& r) {
    Shutter s;
    s.open = r.f64("open");
    s.close = r.f64("close");
    if (!validShutter(s)) r.fail("the shutter does not open before it closes within [-1, 1]");
    return s;
  });
}

ExtensionBlock encodeVelocities(const std::vector<Vec3>& velocities) {
  Bytes bytes;
  ByteWriter w(bytes);
  const auto valid = [](const Vec3& v) {
    return validVelocity(v) ? std::string() : std::string("not finite or beyond 1e9 m/s");
  };
  writeRecords(w, velocities, "encodeVelocities", "vertex", valid, [&](const Vec3& v) {
    for (int k = 0; k < 3; ++k) w.f32(static_cast<float>(v[k]));
  });
  return {kVelocitiesTag, std::move(bytes)};
}

std::optional<std::vector<Vec3>> decodeVelocities(const std::vector<ExtensionBlock>& frameBlocks) {
  return decodeBlock(frameBlocks, kVelocitiesTag, [](SubBlockReader& r) {
    return readRecords<Vec3>(r, 12, "vertex", [&](Vec3& v) {
      for (int k = 0; k < 3; ++k) v[k] = r.f32("velocity");
      if (!validVelocity(v)) r.fail("the velocity is not finite or beyond 1e9 m/s");
    });
  });
}

ExtensionBlock encodePropVelocities(const std::vector<Mat4>& derivatives) {
  Bytes bytes;
  ByteWriter w(bytes);
  const auto valid = [](const Mat4& d) {
    return d.allFinite() ? std::string() : std::string("not finite");
  };
  writeRecords(w, derivatives, "encodePropVelocities", "prop", valid, [&](const Mat4& d) {
    for (int c = 0; c < 4; ++c)
      for (int row = 0; row < 4; ++row) w.f64(d(row, c));
  });
  return {kPropVelocitiesTag, std::move(bytes)};
}

std::optional<std::vector<Mat4>> decodePropVelocities(
    const std::vector<ExtensionBlock>& frameBlocks) {
  return decodeBlock(frameBlocks, kPropVelocitiesTag, [](SubBlockReader& r) {
    return readRecords<Mat4>(r, 128, "prop", [&](Mat4& d) {
      for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) d(row, c) = r.f64("derivative");
      if (!d.allFinite()) r.fail("the derivative is not finite");
    });
  });
}

}  // namespace crumple::cache
