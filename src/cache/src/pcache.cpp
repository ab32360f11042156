// The .pcache writer and reader. Byte layout: docs/PCACHE.md.
#include "crumple/cache/pcache.hpp"

#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "crumple/core/error.hpp"
#include "pcache_chunks.hpp"

namespace crumple::cache {
namespace {

using namespace detail;

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
  ByteWriter e(bytes);
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
    } catch (const CorruptDataError& e) {
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
    const std::uint64_t footOffset = decoder(trailer.data(), 8).u64("footer offset");
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
    } catch (const CorruptDataError& e) {
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
          } catch (const CorruptDataError& e) {
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
  } catch (const CorruptDataError& e) {
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
