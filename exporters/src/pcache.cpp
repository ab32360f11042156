// The .pcache writer and reader. Byte layout: docs/PCACHE.md.
#include "crumple/exporters/pcache.hpp"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "byte_encoder.hpp"
#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache {
namespace {

static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8,
              "doubles are stored as IEEE-754 binary64");
static_assert(sizeof(int) == 4, "ints are stored as 32-bit two's complement");

using detail::Bytes;
using detail::Encoder;
using detail::Tag;

constexpr std::array<std::uint8_t, 8> kFileMagic{'P', 'C', 'A', 'C', 'H', 'E', 0x00, 0x01};
constexpr std::array<std::uint8_t, 8> kEndMagic{'P', 'C', 'A', 'C', 'H', 'E', 'N', 'D'};
constexpr Tag kHeadTag{'H', 'E', 'A', 'D'};
constexpr Tag kFrameTag{'F', 'R', 'A', 'M'};
constexpr Tag kFootTag{'F', 'O', 'O', 'T'};
constexpr std::uint32_t kHeadVersion = 1;
constexpr std::uint32_t kFrameVersion = 1;
constexpr std::uint32_t kFootVersion = 1;
constexpr std::uint64_t kChunkPrefix = 16;                  // tag, version, payload length
constexpr std::uint64_t kChunkOverhead = kChunkPrefix + 4;  // ... and the CRC after the payload
constexpr std::uint64_t kTrailerSize = 16;                  // footer offset, end magic
constexpr std::uint64_t kFootEntrySize = 16;                // frame, offset, topology source
constexpr std::uint8_t kFlagTopology = 0x01;

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

// Malformed payload bytes. Callers turn it into InputError (header) or
// CorruptDataError (frames) with the file and frame named.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Decoder {
 public:
  Decoder(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::uint8_t u8(const char* what) { return *take(1, what); }
  std::uint32_t u32(const char* what) { return static_cast<std::uint32_t>(get(4, what)); }
  std::uint64_t u64(const char* what) { return get(8, what); }
  int i32(const char* what) { return static_cast<std::int32_t>(u32(what)); }
  double f64(const char* what) { return std::bit_cast<double>(u64(what)); }
  Tag tag(const char* what) {
    Tag t;
    std::memcpy(t.data(), take(4, what), 4);
    return t;
  }
  // A u32 element count, checked against the bytes left so that a damaged
  // count cannot trigger a huge allocation.
  std::size_t count(std::size_t elementSize, const char* what) {
    const std::size_t n = u32(what);
    if (n > remaining() / elementSize)
      throw FormatError(std::string(what) + ": count " + std::to_string(n) +
                        " runs past the end of the chunk");
    return n;
  }
  std::string str(const char* what) {
    const std::size_t n = count(1, what);
    const auto* p = take(n, what);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  const std::uint8_t* take(std::size_t n, const char* what) {
    if (n > remaining()) throw FormatError(std::string(what) + " runs past the end of the chunk");
    const auto* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  std::size_t remaining() const { return size_ - pos_; }
  void expectEnd(const char* what) const {
    if (remaining() != 0)
      throw FormatError(std::to_string(remaining()) + " unexpected bytes after the " + what);
  }

 private:
  std::uint64_t get(int bytes, const char* what) {
    const auto* p = take(static_cast<std::size_t>(bytes), what);
    std::uint64_t v = 0;
    for (int k = 0; k < bytes; ++k) v |= static_cast<std::uint64_t>(p[k]) << (8 * k);
    return v;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// --- Field groups ----------------------------------------------------------

void encodeInts(Encoder& e, const std::vector<int>& v, const char* what) {
  e.count(v.size(), what);
  for (int x : v) e.i32(x);
}
std::vector<int> decodeInts(Decoder& d, const char* what) {
  std::vector<int> v(d.count(4, what));
  for (int& x : v) x = d.i32(what);
  return v;
}

template <std::size_t N>
void encodeIntTuples(Encoder& e, const std::vector<std::array<int, N>>& v, const char* what) {
  e.count(v.size(), what);
  for (const auto& t : v)
    for (int x : t) e.i32(x);
}
template <std::size_t N>
std::vector<std::array<int, N>> decodeIntTuples(Decoder& d, const char* what) {
  std::vector<std::array<int, N>> v(d.count(4 * N, what));
  for (auto& t : v)
    for (int& x : t) x = d.i32(what);
  return v;
}

template <typename VecT>
void encodeVectors(Encoder& e, const std::vector<VecT>& v, const char* what) {
  e.count(v.size(), what);
  for (const auto& p : v)
    for (Eigen::Index k = 0; k < p.size(); ++k) e.f64(p[k]);
}
template <typename VecT>
std::vector<VecT> decodeVectors(Decoder& d, const char* what) {
  constexpr int kDim = VecT::RowsAtCompileTime;
  std::vector<VecT> v(d.count(8 * kDim, what));
  for (auto& p : v)
    for (int k = 0; k < kDim; ++k) p[k] = d.f64(what);
  return v;
}

void encodeExtensions(Encoder& e, const std::vector<ExtensionBlock>& blocks) {
  e.count(blocks.size(), "extension sub-blocks");
  for (const auto& b : blocks) {
    e.tag(b.tag);
    e.u64(b.data.size());
    e.raw(b.data.data(), b.data.size());
  }
}
std::vector<ExtensionBlock> decodeExtensions(Decoder& d) {
  std::vector<ExtensionBlock> blocks(d.count(12, "extension sub-blocks"));
  for (auto& b : blocks) {
    b.tag = d.tag("extension sub-block tag");
    const std::uint64_t n = d.u64("extension sub-block length");
    if (n > d.remaining())
      throw FormatError("extension sub-block '" + tagText(b.tag) +
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
  Encoder e(out);
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
  Encoder(out).u32(crc);
}

// --- Header, frames, footer ------------------------------------------------

void encodeHeader(Bytes& out, const CacheHeader& h) {
  const std::size_t start = beginChunk(out, kHeadTag, kHeadVersion);
  Encoder e(out);
  e.u32(kFormatVersion);
  e.f64(h.fps);
  e.i32(h.frameStart);
  e.i32(h.frameEnd);
  e.i32(h.substeps);
  e.u64(h.seed);
  e.str(h.sceneName, "bytes in sceneName");
  e.str(h.sceneFile, "bytes in sceneFile");
  e.str(h.sceneText, "bytes in sceneText");
  e.f64(h.sheetWidth);
  e.f64(h.sheetHeight);
  e.str(h.paperName, "bytes in paperName");
  e.f64(h.paperThickness);
  e.count(h.handleNames.size(), "handle names");
  for (const auto& name : h.handleNames) e.str(name, "bytes in a handle name");
  encodeExtensions(e, h.extensions);
  endChunk(out, start);
}

CacheHeader decodeHeader(const Bytes& payload) {
  Decoder d(payload.data(), payload.size());
  CacheHeader h;
  h.formatVersion = d.u32("formatVersion");
  if (h.formatVersion != kFormatVersion)
    throw FormatError("format version " + std::to_string(h.formatVersion) +
                      " is not supported (this reader reads version " +
                      std::to_string(kFormatVersion) + ")");
  h.fps = d.f64("fps");
  h.frameStart = d.i32("frameStart");
  h.frameEnd = d.i32("frameEnd");
  h.substeps = d.i32("substeps");
  h.seed = d.u64("seed");
  h.sceneName = d.str("sceneName");
  h.sceneFile = d.str("sceneFile");
  h.sceneText = d.str("sceneText");
  h.sheetWidth = d.f64("sheetWidth");
  h.sheetHeight = d.f64("sheetHeight");
  h.paperName = d.str("paperName");
  h.paperThickness = d.f64("paperThickness");
  h.handleNames.resize(d.count(4, "handle names"));
  for (auto& name : h.handleNames) name = d.str("handle name");
  h.extensions = decodeExtensions(d);
  d.expectEnd("header");
  return h;
}

void encodeTopology(Bytes& out, const FrameRecord& f) {
  Encoder e(out);
  encodeIntTuples(e, f.triangles, "triangles");
  encodeInts(e, f.regionOfTriangle, "regionOfTriangle entries");
  e.count(f.regionTypes.size(), "region types");
  e.raw(f.regionTypes.data(), f.regionTypes.size());
  encodeVectors(e, f.pattern, "pattern vertices");
}

// The FRAM chunk of f; topology is the encoded topology section, or null to
// leave it out.
void encodeFrame(Bytes& out, const FrameRecord& f, const Bytes* topology) {
  const std::size_t start = beginChunk(out, kFrameTag, kFrameVersion);
  Encoder e(out);
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

struct DecodedFrame {
  FrameRecord record;
  bool hasTopology = false;
};

DecodedFrame decodeFrame(const Bytes& payload) {
  Decoder d(payload.data(), payload.size());
  DecodedFrame out;
  FrameRecord& f = out.record;
  f.frame = d.i32("frame number");
  f.time = d.f64("time");
  const std::uint8_t flags = d.u8("flags");
  if (flags & ~kFlagTopology) throw FormatError("unknown flag bits " + hex32(flags));
  out.hasTopology = (flags & kFlagTopology) != 0;
  if (out.hasTopology) {
    f.triangles = decodeIntTuples<3>(d, "triangles");
    f.regionOfTriangle = decodeInts(d, "regionOfTriangle");
    const std::size_t nTypes = d.count(1, "region types");
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
  d.expectEnd("frame");
  return out;
}

struct IndexEntry {
  int frame = 0;
  std::uint64_t offset = 0;          // of the FRAM chunk
  std::uint32_t topologySource = 0;  // index of the frame whose chunk holds the topology
};

void encodeFooter(Bytes& out, const std::vector<IndexEntry>& index) {
  const std::size_t start = beginChunk(out, kFootTag, kFootVersion);
  Encoder e(out);
  e.count(index.size(), "frames");
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
  Decoder d(payload.data(), payload.size());
  std::vector<IndexEntry> index(d.count(kFootEntrySize, "frame table"));
  for (std::size_t i = 0; i < index.size(); ++i) {
    IndexEntry& e = index[i];
    e.frame = d.i32("frame table");
    e.offset = d.u64("frame table");
    e.topologySource = d.u32("frame table");
    const std::string where = "frame table entry " + std::to_string(i) + ": ";
    const std::uint64_t minOffset = i == 0 ? dataStart : index[i - 1].offset + kChunkOverhead;
    if (e.offset < minOffset || e.offset > footOffset - kChunkOverhead)
      throw FormatError(where + "offset " + std::to_string(e.offset) + " out of range");
    if (i > 0 && e.frame <= index[i - 1].frame)
      throw FormatError(where + "frame numbers do not increase");
    if (e.topologySource > i || index[e.topologySource].topologySource != e.topologySource)
      throw FormatError(where + "bad topology source " + std::to_string(e.topologySource));
  }
  decodeExtensions(d);
  d.expectEnd("footer");
  return index;
}

// --- File access -----------------------------------------------------------

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

std::string errnoText(int err) { return std::strerror(err); }

// An open cache file and its size at opening time.
struct InputFile {
  FilePtr file;
  std::uint64_t size = 0;

  explicit InputFile(const std::string& path) {
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

  // Reads exactly n bytes at offset; false if the file has fewer.
  bool readAt(std::uint64_t offset, void* out, std::size_t n) const {
    if (offset > size || n > size - offset) return false;
    if (::fseeko(file.get(), static_cast<off_t>(offset), SEEK_SET) != 0) return false;
    return std::fread(out, 1, n, file.get()) == n;
  }
};

struct Chunk {
  Tag tag{};
  std::uint32_t version = 0;
  Bytes payload;
  std::uint64_t end = 0;  // offset just past its CRC
  bool tagKnown = false;  // the tag was readable even if the chunk is not
};

enum class ChunkStatus { Ok, Truncated, BadCrc };

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
  Decoder d(prefix.data(), prefix.size());
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
  const std::uint32_t stored = Decoder(crcBytes.data(), 4).u32("crc");
  const std::uint32_t computed =
      crc32(c.payload.data(), c.payload.size(), crc32(prefix.data(), prefix.size()));
  if (stored != computed) {
    problem = "CRC mismatch in the chunk at byte " + std::to_string(offset) + " (stored " +
              hex32(stored) + ", computed " + hex32(computed) + ")";
    return ChunkStatus::BadCrc;
  }
  return ChunkStatus::Ok;
}

struct Topology {
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> regionOfTriangle;
  std::vector<std::uint8_t> regionTypes;
  std::vector<Vec2> pattern;
};

std::string plural(std::size_t n, const char* word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

}  // namespace

// ===========================================================================
// Writer

struct CacheWriter::Impl {
  std::string path;
  FilePtr file;
  std::uint64_t offset = 0;  // bytes written so far
  std::vector<IndexEntry> index;
  Bytes previousTopology;  // encoded topology section of the last appended frame
  bool failed = false;
  bool closed = false;

  void write(const Bytes& bytes) {
    if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size() ||
        std::fflush(file.get()) != 0) {
      const int err = errno;
      failed = true;
      throw InputError(path, "cannot write cache: " + errnoText(err));
    }
    offset += bytes.size();
  }
};

CacheWriter::CacheWriter(const std::string& path, const CacheHeader& header)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  Bytes bytes(kFileMagic.begin(), kFileMagic.end());
  encodeHeader(bytes, header);
  impl_->file.reset(std::fopen(path.c_str(), "wb"));
  if (!impl_->file) throw InputError(path, "cannot create cache: " + errnoText(errno));
  impl_->write(bytes);
}

CacheWriter::~CacheWriter() = default;  // closes the file; deliberately no footer

void CacheWriter::append(const FrameRecord& frame) {
  Impl& w = *impl_;
  if (w.closed) throw std::logic_error(w.path + ": append() after close()");
  if (w.failed) throw InputError(w.path, "cannot write cache: an earlier write failed");
  if (!w.index.empty() && frame.frame <= w.index.back().frame)
    throw std::invalid_argument(w.path + ": frame " + std::to_string(frame.frame) +
                                " appended after frame " + std::to_string(w.index.back().frame));
  Bytes topology;
  encodeTopology(topology, frame);
  const bool withTopology = w.index.empty() || topology != w.previousTopology;
  Bytes chunk;
  encodeFrame(chunk, frame, withTopology ? &topology : nullptr);
  const auto k = static_cast<std::uint32_t>(w.index.size());
  const IndexEntry entry{frame.frame, w.offset, withTopology ? k : w.index.back().topologySource};
  w.write(chunk);
  w.index.push_back(entry);
  if (withTopology) w.previousTopology = std::move(topology);
}

void CacheWriter::close() {
  Impl& w = *impl_;
  if (w.closed) return;
  if (w.failed) {
    w.file.reset();
    w.closed = true;
    throw InputError(w.path, "cannot finish cache: an earlier write failed");
  }
  const std::uint64_t footOffset = w.offset;
  Bytes bytes;
  encodeFooter(bytes, w.index);
  Encoder e(bytes);
  e.u64(footOffset);
  e.raw(kEndMagic.data(), kEndMagic.size());
  w.write(bytes);
  w.closed = true;
  if (std::fclose(w.file.release()) != 0)
    throw InputError(w.path, "cannot write cache: " + errnoText(errno));
}

std::size_t CacheWriter::framesWritten() const { return impl_->index.size(); }

// ===========================================================================
// Reader

struct CacheReader::Impl {
  std::string path;
  CacheHeader header;
  std::vector<IndexEntry> index;
  bool recovered = false;
  std::vector<CacheIssue> issues;

  // The topology of frame cachedSource, kept for the frames that share it.
  mutable std::mutex topologyMutex;
  mutable std::shared_ptr<const Topology> cachedTopology;
  mutable std::size_t cachedSource = 0;

  std::string frameWhere(std::size_t i) const {
    return path + ": frame " + std::to_string(index[i].frame) + " (index " + std::to_string(i) +
           "): ";
  }

  // Reads, checks and decodes frame i's own chunk (topology not carried).
  DecodedFrame loadFrame(const InputFile& in, std::size_t i) const {
    Chunk c;
    std::string problem;
    if (readChunk(in, index[i].offset, c, problem) != ChunkStatus::Ok)
      throw CorruptDataError(frameWhere(i) + problem);
    if (c.tag != kFrameTag)
      throw CorruptDataError(frameWhere(i) + "the chunk at byte " +
                             std::to_string(index[i].offset) + " is '" + tagText(c.tag) +
                             "', not a frame");
    if (c.version != kFrameVersion)
      throw CorruptDataError(frameWhere(i) + "unsupported frame chunk version " +
                             std::to_string(c.version));
    DecodedFrame d;
    try {
      d = decodeFrame(c.payload);
    } catch (const FormatError& e) {
      throw CorruptDataError(frameWhere(i) + e.what());
    }
    if (d.record.frame != index[i].frame)
      throw CorruptDataError(frameWhere(i) + "the chunk holds frame " +
                             std::to_string(d.record.frame));
    const bool isSource = index[i].topologySource == i;
    if (d.hasTopology != isSource)
      throw CorruptDataError(frameWhere(i) + (isSource ? "topology missing from the chunk"
                                                       : "unexpected topology in the chunk"));
    return d;
  }

  FrameRecord loadFullFrame(const InputFile& in, std::size_t index) const;

  std::shared_ptr<const Topology> topologyOf(const InputFile& in, std::size_t source) const {
    {
      std::lock_guard lock(topologyMutex);
      if (cachedTopology && cachedSource == source) return cachedTopology;
    }
    DecodedFrame d = loadFrame(in, source);
    auto t = std::make_shared<Topology>();
    t->triangles = std::move(d.record.triangles);
    t->regionOfTriangle = std::move(d.record.regionOfTriangle);
    t->regionTypes = std::move(d.record.regionTypes);
    t->pattern = std::move(d.record.pattern);
    remember(source, t);
    return t;
  }

  void remember(std::size_t source, std::shared_ptr<const Topology> t) const {
    std::lock_guard lock(topologyMutex);
    cachedTopology = std::move(t);
    cachedSource = source;
  }

  // Uses the trailer and footer; returns why not if they are unusable.
  std::optional<std::string> tryFooter(const InputFile& in, std::uint64_t dataStart) {
    std::array<std::uint8_t, kTrailerSize> trailer{};
    if (in.size < dataStart + kTrailerSize ||
        !in.readAt(in.size - kTrailerSize, trailer.data(), trailer.size()) ||
        !std::equal(kEndMagic.begin(), kEndMagic.end(), trailer.begin() + 8))
      return "no footer";
    const std::uint64_t footOffset = Decoder(trailer.data(), 8).u64("footer offset");
    if (footOffset < dataStart || footOffset > in.size - kTrailerSize)
      return "footer damaged (footer offset " + std::to_string(footOffset) + " out of range)";
    Chunk c;
    std::string problem;
    if (readChunk(in, footOffset, c, problem) != ChunkStatus::Ok)
      return "footer damaged (" + problem + ")";
    if (c.tag != kFootTag || c.end != in.size - kTrailerSize)
      return "footer damaged (no footer chunk at byte " + std::to_string(footOffset) + ")";
    if (c.version != kFootVersion)
      return "footer unreadable (unsupported version " + std::to_string(c.version) + ")";
    try {
      index = decodeFooter(c.payload, dataStart, footOffset);
    } catch (const FormatError& e) {
      return std::string("footer damaged (") + e.what() + ")";
    }
    return std::nullopt;
  }

  // Walks the chunks after the header, keeping every complete, CRC-valid
  // frame up to the first bad or truncated chunk.
  void scan(const InputFile& in, std::uint64_t dataStart, const std::string& why) {
    index.clear();
    recovered = true;
    std::uint64_t pos = dataStart;
    std::string stop;
    int stopIndex = -1;
    while (true) {
      const std::size_t k = index.size();
      const std::string frameName = "frame index " + std::to_string(k);
      if (pos == in.size) {
        stop = "the file ends after the last complete chunk, at byte " + std::to_string(pos);
        break;
      }
      Chunk c;
      std::string problem;
      if (readChunk(in, pos, c, problem) != ChunkStatus::Ok) {
        const bool frame = !c.tagKnown || c.tag == kFrameTag;
        const bool wasTruncated = problem.starts_with("truncated");
        stop = (frame ? frameName : "chunk '" + tagText(c.tag) + "'") +
               (wasTruncated ? " " : ": ") + problem;
        if (frame) stopIndex = static_cast<int>(k);
        break;
      }
      if (c.tag == kFootTag) {
        stop =
            "a footer chunk at byte " + std::to_string(pos) + " has a missing or damaged trailer";
        break;
      }
      if (c.tag == kFrameTag) {
        std::string bad;
        DecodedFrame d;
        if (c.version != kFrameVersion) {
          bad = "unsupported frame chunk version " + std::to_string(c.version);
        } else {
          try {
            d = decodeFrame(c.payload);
          } catch (const FormatError& e) {
            bad = e.what();
          }
        }
        if (bad.empty() && k == 0 && !d.hasTopology) bad = "the first frame has no topology";
        if (bad.empty() && k > 0 && d.record.frame <= index.back().frame)
          bad = "frame " + std::to_string(d.record.frame) + " does not follow frame " +
                std::to_string(index.back().frame);
        if (!bad.empty()) {
          stop = frameName + " at byte " + std::to_string(pos) + ": " + bad;
          stopIndex = static_cast<int>(k);
          break;
        }
        const auto self = static_cast<std::uint32_t>(k);
        index.push_back({d.record.frame, pos, d.hasTopology ? self : index.back().topologySource});
      }
      // Any other chunk type belongs to a later format revision: skipped.
      pos = c.end;
    }
    issues.push_back({stopIndex,
                      why + ": recovered " + plural(index.size(), "complete frame") + "; " + stop,
                      std::nullopt});
  }
};

CacheReader::CacheReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.path = path;
  const InputFile in(path);
  std::array<std::uint8_t, 8> magic{};
  if (!in.readAt(0, magic.data(), magic.size()) || magic != kFileMagic)
    throw InputError(path, "not a .pcache file (bad magic)");
  Chunk head;
  std::string problem;
  if (readChunk(in, magic.size(), head, problem) != ChunkStatus::Ok)
    throw InputError(path, "damaged cache header: " + problem);
  if (head.tag != kHeadTag)
    throw InputError(path, "damaged cache header: first chunk is '" + tagText(head.tag) + "'");
  if (head.version != kHeadVersion)
    throw InputError(path, "unsupported cache header version " + std::to_string(head.version));
  try {
    r.header = decodeHeader(head.payload);
  } catch (const FormatError& e) {
    throw InputError(path, std::string("damaged cache header: ") + e.what());
  }
  if (const std::string problem = validate(r.header); !problem.empty())
    throw InputError(path, "damaged cache header: " + problem);
  if (auto why = r.tryFooter(in, head.end)) r.scan(in, head.end, *why);
}

CacheReader::~CacheReader() = default;
CacheReader::CacheReader(CacheReader&&) noexcept = default;
CacheReader& CacheReader::operator=(CacheReader&&) noexcept = default;

const CacheHeader& CacheReader::header() const { return impl_->header; }
std::size_t CacheReader::frameCount() const { return impl_->index.size(); }
bool CacheReader::recovered() const { return impl_->recovered; }
const std::vector<CacheIssue>& CacheReader::issues() const { return impl_->issues; }
const std::string& CacheReader::path() const { return impl_->path; }

int CacheReader::frameNumber(std::size_t index) const { return impl_->index.at(index).frame; }

std::size_t CacheReader::topologySource(std::size_t index) const {
  return impl_->index.at(index).topologySource;
}

FrameRecord CacheReader::readFrame(std::size_t index) const {
  const Impl& r = *impl_;
  if (index >= r.index.size())
    throw std::out_of_range(r.path + ": frame index " + std::to_string(index) + " of " +
                            std::to_string(r.index.size()));
  const InputFile in(r.path);
  FrameRecord f = r.loadFullFrame(in, index);
  if (const std::string problem = validate(f, r.header); !problem.empty())
    throw CorruptDataError(r.frameWhere(index) + problem);
  return f;
}

std::vector<CacheIssue> CacheReader::verifyAll() const {
  const Impl& r = *impl_;
  std::vector<CacheIssue> issues;
  std::optional<InputFile> in;
  try {
    in.emplace(r.path);
  } catch (const InputError& e) {
    issues.push_back({-1, e.what(), std::nullopt});
    return issues;
  }
  for (std::size_t i = 0; i < r.index.size(); ++i) {
    try {
      const FrameRecord f = r.loadFullFrame(*in, i);
      if (const std::string problem = validate(f, r.header); !problem.empty())
        throw CorruptDataError(r.frameWhere(i) + problem);
    } catch (const CorruptDataError& e) {
      issues.push_back({static_cast<int>(i), e.what(), r.index[i].frame});
    }
  }
  return issues;
}

// Frame `index` with its topology carried from the frame that holds it.
FrameRecord CacheReader::Impl::loadFullFrame(const InputFile& in, std::size_t index) const {
  const Impl& r = *this;
  DecodedFrame d = r.loadFrame(in, index);
  FrameRecord& f = d.record;
  const std::size_t source = r.index[index].topologySource;
  if (source != index) {
    std::shared_ptr<const Topology> t;
    try {
      t = r.topologyOf(in, source);
    } catch (const CorruptDataError& e) {
      throw CorruptDataError(r.frameWhere(index) + "its topology is unreadable: " + e.what());
    }
    f.triangles = t->triangles;
    f.regionOfTriangle = t->regionOfTriangle;
    f.regionTypes = t->regionTypes;
    f.pattern = t->pattern;
  } else if (index + 1 < r.index.size() && r.index[index + 1].topologySource == index) {
    // The next frames share this topology: keep a copy for them.
    r.remember(index, std::make_shared<const Topology>(
                          Topology{f.triangles, f.regionOfTriangle, f.regionTypes, f.pattern}));
  }
  return std::move(f);
}

// ===========================================================================
// Resume

CacheWriter::CacheWriter() : impl_(std::make_unique<Impl>()) {}

std::unique_ptr<CacheWriter> CacheWriter::resume(const std::string& path, const CacheHeader& header,
                                                 std::size_t keepFrames) {
  const CacheReader reader(path);
  if (reader.frameCount() < keepFrames)
    throw InputError(path, "holds " + plural(reader.frameCount(), "complete frame") + ", " +
                               std::to_string(keepFrames) + " needed to resume");
  // The header must be the one this run writes, byte for byte.
  Bytes expected(kFileMagic.begin(), kFileMagic.end());
  encodeHeader(expected, header);
  const InputFile in(path);
  Bytes found(expected.size());
  if (!in.readAt(0, found.data(), found.size()) || found != expected)
    throw InputError(path, "was not written by this shot (its header differs): cannot resume it");
  // Where the kept frames end: the next frame's chunk, else the last kept
  // chunk's end.
  std::uint64_t end = expected.size();
  if (keepFrames > 0) {
    const std::uint64_t last = reader.impl_->index[keepFrames - 1].offset;
    Chunk c;
    std::string problem;
    if (readChunk(in, last, c, problem) != ChunkStatus::Ok)
      throw InputError(path, "cannot resume: " + problem);
    end = c.end;
  }
  std::unique_ptr<CacheWriter> writer(new CacheWriter());
  Impl& w = *writer->impl_;
  w.path = path;
  w.index.assign(reader.impl_->index.begin(),
                 reader.impl_->index.begin() + static_cast<std::ptrdiff_t>(keepFrames));
  if (keepFrames > 0) encodeTopology(w.previousTopology, reader.readFrame(keepFrames - 1));
  std::error_code ec;
  std::filesystem::resize_file(path, end, ec);
  if (ec) throw InputError(path, "cannot resume: " + ec.message());
  w.file.reset(std::fopen(path.c_str(), "r+b"));
  if (!w.file || std::fseek(w.file.get(), static_cast<long>(end), SEEK_SET) != 0)
    throw InputError(path, "cannot resume: " + errnoText(errno));
  w.offset = end;
  return writer;
}

}  // namespace crumple::cache
