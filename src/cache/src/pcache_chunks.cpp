// The .pcache chunks: payload codecs and framing. Byte layout: docs/PCACHE.md.
#include "pcache_chunks.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache::detail {

static_assert(sizeof(int) == 4, "ints are stored as 32-bit two's complement");

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", static_cast<unsigned>(v));
  return buf;
}

std::string tagText(const Tag& tag) {
  std::string s;
  for (char c : tag) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      s += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      s += buf;
    }
  }
  return s;
}

// Malformed payload bytes are CorruptDataError (the core reader's); callers
// turn them into InputError (header) or name the file and frame.
ByteReader decoder(const std::uint8_t* data, std::size_t size) {
  return ByteReader(std::span<const std::uint8_t>(data, size), {});
}

namespace {

// --- Field groups ----------------------------------------------------------

void encodeInts(ByteWriter& e, const std::vector<int>& v, const char* what) {
  e.count32(v.size(), what);
  for (int x : v) e.i32(x);
}
std::vector<int> decodeInts(ByteReader& d, const char* what) {
  std::vector<int> v(d.count32(4, what));
  for (int& x : v) x = d.i32(what);
  return v;
}

template <std::size_t N>
void encodeIntTuples(ByteWriter& e, const std::vector<std::array<int, N>>& v, const char* what) {
  e.count32(v.size(), what);
  for (const auto& t : v)
    for (int x : t) e.i32(x);
}
template <std::size_t N>
std::vector<std::array<int, N>> decodeIntTuples(ByteReader& d, const char* what) {
  std::vector<std::array<int, N>> v(d.count32(4 * N, what));
  for (auto& t : v)
    for (int& x : t) x = d.i32(what);
  return v;
}

template <typename VecT>
void encodeVectors(ByteWriter& e, const std::vector<VecT>& v, const char* what) {
  e.count32(v.size(), what);
  for (const auto& p : v)
    for (Eigen::Index k = 0; k < p.size(); ++k) e.f64(p[k]);
}
template <typename VecT>
std::vector<VecT> decodeVectors(ByteReader& d, const char* what) {
  constexpr int kDim = VecT::RowsAtCompileTime;
  std::vector<VecT> v(d.count32(8 * kDim, what));
  for (auto& p : v)
    for (int k = 0; k < kDim; ++k) p[k] = d.f64(what);
  return v;
}

void encodeExtensions(ByteWriter& e, const std::vector<ExtensionBlock>& blocks) {
  e.count32(blocks.size(), "extension sub-blocks");
  for (const auto& b : blocks) {
    e.tag(b.tag);
    e.u64(b.data.size());
    e.raw(b.data.data(), b.data.size());
  }
}
std::vector<ExtensionBlock> decodeExtensions(ByteReader& d) {
  std::vector<ExtensionBlock> blocks(d.count32(12, "extension sub-blocks"));
  for (auto& b : blocks) {
    b.tag = d.tag("extension sub-block tag");
    const std::uint64_t n = d.u64("extension sub-block length");
    if (n > d.remaining())
      throw CorruptDataError("extension sub-block '" + tagText(b.tag) +
                             "' runs past the end of the chunk");
    const auto* p = d.take(static_cast<std::size_t>(n), "extension sub-block");
    b.data.assign(p, p + n);
  }
  return blocks;
}

// --- Chunks ----------------------------------------------------------------

// Starts a chunk at the end of out; returns where it starts.
std::size_t beginChunk(Bytes& out, const Tag& tag, std::uint32_t version) {
  const std::size_t start = out.size();
  ByteWriter e(out);
  e.tag(tag);
  e.u32(version);
  e.u64(0);  // payload length, patched by endChunk
  return start;
}

// Patches the payload length and appends the CRC of tag..payload.
void endChunk(Bytes& out, std::size_t start) {
  const std::uint64_t length = out.size() - start - kChunkPrefix;
  for (int k = 0; k < 8; ++k) out[start + 8 + k] = static_cast<std::uint8_t>(length >> (8 * k));
  const std::uint32_t crc = crc32(out.data() + start, out.size() - start);
  ByteWriter(out).u32(crc);
}

}  // namespace

// --- Header, frames, footer ------------------------------------------------

void encodeHeader(Bytes& out, const CacheHeader& h) {
  const std::size_t start = beginChunk(out, kHeadTag, kHeadVersion);
  ByteWriter e(out);
  e.u32(kFormatVersion);
  e.f64(h.fps);
  e.i32(h.frameStart);
  e.i32(h.frameEnd);
  e.i32(h.substeps);
  e.u64(h.seed);
  e.str32(h.sceneName, "bytes in sceneName");
  e.str32(h.sceneFile, "bytes in sceneFile");
  e.str32(h.sceneText, "bytes in sceneText");
  e.f64(h.sheetWidth);
  e.f64(h.sheetHeight);
  e.str32(h.paperName, "bytes in paperName");
  e.f64(h.paperThickness);
  e.count32(h.handleNames.size(), "handle names");
  for (const auto& name : h.handleNames) e.str32(name, "bytes in a handle name");
  encodeExtensions(e, h.extensions);
  endChunk(out, start);
}

CacheHeader decodeHeader(const Bytes& payload) {
  ByteReader d = decoder(payload.data(), payload.size());
  CacheHeader h;
  h.formatVersion = d.u32("formatVersion");
  if (h.formatVersion != kFormatVersion)
    throw CorruptDataError("format version " + std::to_string(h.formatVersion) +
                           " is not supported (this reader reads version " +
                           std::to_string(kFormatVersion) + ")");
  h.fps = d.f64("fps");
  h.frameStart = d.i32("frameStart");
  h.frameEnd = d.i32("frameEnd");
  h.substeps = d.i32("substeps");
  h.seed = d.u64("seed");
  h.sceneName = d.str32("sceneName");
  h.sceneFile = d.str32("sceneFile");
  h.sceneText = d.str32("sceneText");
  h.sheetWidth = d.f64("sheetWidth");
  h.sheetHeight = d.f64("sheetHeight");
  h.paperName = d.str32("paperName");
  h.paperThickness = d.f64("paperThickness");
  h.handleNames.resize(d.count32(4, "handle names"));
  for (auto& name : h.handleNames) name = d.str32("handle name");
  h.extensions = decodeExtensions(d);
  d.expectEnd();
  return h;
}

void encodeTopology(Bytes& out, const FrameRecord& f) {
  ByteWriter e(out);
  encodeIntTuples(e, f.triangles, "triangles");
  encodeInts(e, f.regionOfTriangle, "regionOfTriangle entries");
  e.count32(f.regionTypes.size(), "region types");
  e.raw(f.regionTypes.data(), f.regionTypes.size());
  encodeVectors(e, f.pattern, "pattern vertices");
}

// The FRAM chunk of f; topology is the encoded topology section, or null to
// leave it out.
void encodeFrame(Bytes& out, const FrameRecord& f, const Bytes* topology) {
  const std::size_t start = beginChunk(out, kFrameTag, kFrameVersion);
  ByteWriter e(out);
  e.i32(f.frame);
  e.f64(f.time);
  e.u8(topology ? kFlagTopology : 0);
  if (topology) e.raw(topology->data(), topology->size());
  encodeVectors(e, f.positions, "positions");
  encodeInts(e, f.singularVertices, "singular vertices");
  encodeInts(e, f.junctionVertices, "junction vertices");
  encodeIntTuples(e, f.rulings, "rulings");
  e.u32(f.tearCount);
  encodeInts(e, f.handleVertices, "handle vertices");
  encodeVectors(e, f.handleTargets, "handle targets");
  for (int k = 0; k < 3; ++k) e.f64(f.camera.position[k]);
  e.f64(f.camera.rotation.w());
  e.f64(f.camera.rotation.x());
  e.f64(f.camera.rotation.y());
  e.f64(f.camera.rotation.z());
  e.f64(f.camera.yfov);
  encodeExtensions(e, f.extensions);
  endChunk(out, start);
}

DecodedFrame decodeFrame(const Bytes& payload) {
  ByteReader d = decoder(payload.data(), payload.size());
  DecodedFrame out;
  FrameRecord& f = out.record;
  f.frame = d.i32("frame number");
  f.time = d.f64("time");
  const std::uint8_t flags = d.u8("flags");
  if (flags & ~kFlagTopology) throw CorruptDataError("unknown flag bits " + hex32(flags));
  out.hasTopology = (flags & kFlagTopology) != 0;
  if (out.hasTopology) {
    f.triangles = decodeIntTuples<3>(d, "triangles");
    f.regionOfTriangle = decodeInts(d, "regionOfTriangle");
    const std::size_t nTypes = d.count32(1, "region types");
    const auto* p = d.take(nTypes, "region types");
    f.regionTypes.assign(p, p + nTypes);
    f.pattern = decodeVectors<Vec2>(d, "pattern");
  }
  f.positions = decodeVectors<Vec3>(d, "positions");
  f.singularVertices = decodeInts(d, "singular vertices");
  f.junctionVertices = decodeInts(d, "junction vertices");
  f.rulings = decodeIntTuples<2>(d, "rulings");
  f.tearCount = d.u32("tearCount");
  f.handleVertices = decodeInts(d, "handle vertices");
  f.handleTargets = decodeVectors<Vec3>(d, "handle targets");
  for (int k = 0; k < 3; ++k) f.camera.position[k] = d.f64("camera");
  const double w = d.f64("camera");
  const double x = d.f64("camera");
  const double y = d.f64("camera");
  const double z = d.f64("camera");
  f.camera.rotation = Quat(w, x, y, z);
  f.camera.yfov = d.f64("camera");
  f.extensions = decodeExtensions(d);
  d.expectEnd();
  return out;
}

void encodeFooter(Bytes& out, const std::vector<IndexEntry>& index) {
  const std::size_t start = beginChunk(out, kFootTag, kFootVersion);
  ByteWriter e(out);
  e.count32(index.size(), "frames");
  for (const auto& entry : index) {
    e.i32(entry.frame);
    e.u64(entry.offset);
    e.u32(entry.topologySource);
  }
  encodeExtensions(e, {});
  endChunk(out, start);
}

// Checks the footer's table against what a writer can produce.
std::vector<IndexEntry> decodeFooter(const Bytes& payload, std::uint64_t dataStart,
                                     std::uint64_t footOffset) {
  ByteReader d = decoder(payload.data(), payload.size());
  std::vector<IndexEntry> index(d.count32(kFootEntrySize, "frame table"));
  for (std::size_t i = 0; i < index.size(); ++i) {
    IndexEntry& e = index[i];
    e.frame = d.i32("frame table");
    e.offset = d.u64("frame table");
    e.topologySource = d.u32("frame table");
    const std::string where = "frame table entry " + std::to_string(i) + ": ";
    const std::uint64_t minOffset = i == 0 ? dataStart : index[i - 1].offset + kChunkOverhead;
    if (e.offset < minOffset || e.offset > footOffset - kChunkOverhead)
      throw CorruptDataError(where + "offset " + std::to_string(e.offset) + " out of range");
    if (i > 0 && e.frame <= index[i - 1].frame)
      throw CorruptDataError(where + "frame numbers do not increase");
    if (e.topologySource > i || index[e.topologySource].topologySource != e.topologySource)
      throw CorruptDataError(where + "bad topology source " + std::to_string(e.topologySource));
  }
  decodeExtensions(d);
  d.expectEnd();
  return index;
}

// --- File access -----------------------------------------------------------

std::string errnoText(int err) { return std::strerror(err); }

InputFile::InputFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "cannot open cache: is a directory");
  file.reset(std::fopen(path.c_str(), "rb"));
  if (!file) throw InputError(path, "cannot open cache: " + errnoText(errno));
  if (::fseeko(file.get(), 0, SEEK_END) != 0)
    throw InputError(path, "cannot read cache: " + errnoText(errno));
  const auto end = ::ftello(file.get());
  if (end < 0) throw InputError(path, "cannot read cache: " + errnoText(errno));
  size = static_cast<std::uint64_t>(end);
}

bool InputFile::readAt(std::uint64_t offset, void* out, std::size_t n) const {
  if (offset > size || n > size - offset) return false;
  if (::fseeko(file.get(), static_cast<off_t>(offset), SEEK_SET) != 0) return false;
  return std::fread(out, 1, n, file.get()) == n;
}

// Reads the chunk at offset and checks its CRC. On failure, problem says what
// went wrong (it starts with "truncated" or "CRC mismatch").
ChunkStatus readChunk(const InputFile& in, std::uint64_t offset, Chunk& c, std::string& problem) {
  std::array<std::uint8_t, kChunkPrefix> prefix{};
  const std::uint64_t avail = in.size > offset ? in.size - offset : 0;
  c.tagKnown = avail >= 4 && in.readAt(offset, c.tag.data(), 4);
  if (!in.readAt(offset, prefix.data(), prefix.size())) {
    problem = "truncated at byte " + std::to_string(in.size) + " (chunk starts at byte " +
              std::to_string(offset) + ", its 16-byte prefix is incomplete)";
    return ChunkStatus::Truncated;
  }
  ByteReader d = decoder(prefix.data(), prefix.size());
  c.tag = d.tag("tag");
  c.version = d.u32("version");
  const std::uint64_t length = d.u64("length");
  if (length > avail - kChunkPrefix || avail - kChunkPrefix - length < 4) {
    problem = "truncated at byte " + std::to_string(in.size) + " (chunk '" + tagText(c.tag) +
              "' starts at byte " + std::to_string(offset) + " and claims " +
              std::to_string(length) + " payload bytes)";
    return ChunkStatus::Truncated;
  }
  c.payload.resize(static_cast<std::size_t>(length));
  std::array<std::uint8_t, 4> crcBytes{};
  if (!in.readAt(offset + kChunkPrefix, c.payload.data(), c.payload.size()) ||
      !in.readAt(offset + kChunkPrefix + length, crcBytes.data(), crcBytes.size())) {
    problem = "truncated: read error in the chunk at byte " + std::to_string(offset);
    return ChunkStatus::Truncated;
  }
  c.end = offset + kChunkPrefix + length + 4;
  const std::uint32_t stored = decoder(crcBytes.data(), 4).u32("crc");
  const std::uint32_t computed =
      crc32(c.payload.data(), c.payload.size(), crc32(prefix.data(), prefix.size()));
  if (stored != computed) {
    problem = "CRC mismatch in the chunk at byte " + std::to_string(offset) + " (stored " +
              hex32(stored) + ", computed " + hex32(computed) + ")";
    return ChunkStatus::BadCrc;
  }
  return ChunkStatus::Ok;
}

}  // namespace crumple::cache::detail
