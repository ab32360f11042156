#pragma once
// The .pcache chunks (docs/PCACHE.md "Layout"): the header, frame and footer
// chunks' payloads, their framing (tag, version, length, CRC-32) and reading
// one chunk from a file. Internal to the cache library: pcache.cpp builds
// the writer, reader and resume on them.
#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/byte_io.hpp"
#include "sub_block.hpp"

namespace crumple::cache::detail {

inline constexpr std::array<std::uint8_t, 8> kFileMagic{'P', 'C', 'A', 'C', 'H', 'E', 0x00, 0x01};
inline constexpr std::array<std::uint8_t, 8> kEndMagic{'P', 'C', 'A', 'C', 'H', 'E', 'N', 'D'};
inline constexpr Tag kHeadTag{'H', 'E', 'A', 'D'};
inline constexpr Tag kFrameTag{'F', 'R', 'A', 'M'};
inline constexpr Tag kFootTag{'F', 'O', 'O', 'T'};
inline constexpr std::uint32_t kHeadVersion = 1;
inline constexpr std::uint32_t kFrameVersion = 1;
inline constexpr std::uint32_t kFootVersion = 1;
inline constexpr std::uint64_t kChunkPrefix = 16;  // tag, version, payload length
inline constexpr std::uint64_t kChunkOverhead =
    kChunkPrefix + 4;                                // ... and the CRC after the payload
inline constexpr std::uint64_t kTrailerSize = 16;    // footer offset, end magic
inline constexpr std::uint64_t kFootEntrySize = 16;  // frame, offset, topology source
inline constexpr std::uint8_t kFlagTopology = 0x01;

std::string hex32(std::uint32_t v);
// A tag as text, unprintable bytes escaped.
std::string tagText(const Tag& tag);

void encodeHeader(Bytes& out, const CacheHeader& h);
CacheHeader decodeHeader(const Bytes& payload);
// The topology section of f (triangles, regions, pattern), as a frame chunk
// carries it.
void encodeTopology(Bytes& out, const FrameRecord& f);
// The FRAM chunk of f; topology is the encoded topology section, or null to
// leave it out.
void encodeFrame(Bytes& out, const FrameRecord& f, const Bytes* topology);
struct DecodedFrame {
  FrameRecord record;
  bool hasTopology = false;
};
DecodedFrame decodeFrame(const Bytes& payload);

struct IndexEntry {
  int frame = 0;
  std::uint64_t offset = 0;          // of the FRAM chunk
  std::uint32_t topologySource = 0;  // index of the frame whose chunk holds the topology
};
void encodeFooter(Bytes& out, const std::vector<IndexEntry>& index);
// Checks the footer's table against what a writer can produce.
std::vector<IndexEntry> decodeFooter(const Bytes& payload, std::uint64_t dataStart,
                                     std::uint64_t footOffset);

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

std::string errnoText(int err);

// An open cache file and its size at opening time.
struct InputFile {
  FilePtr file;
  std::uint64_t size = 0;

  // Throws InputError naming the path when it cannot be opened.
  explicit InputFile(const std::string& path);
  // Reads exactly n bytes at offset; false if the file has fewer.
  bool readAt(std::uint64_t offset, void* out, std::size_t n) const;
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
ChunkStatus readChunk(const InputFile& in, std::uint64_t offset, Chunk& c, std::string& problem);

// Reads fixed-size fields (CRC, footer offset) out of a buffer.
ByteReader decoder(const std::uint8_t* data, std::size_t size);

}  // namespace crumple::cache::detail
