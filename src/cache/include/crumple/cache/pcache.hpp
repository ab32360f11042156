#pragma once
// The .pcache mesh cache (docs/ARCHITECTURE.md "Cache format"): little-endian, chunked,
// versioned. A header chunk, one chunk per frame (topology only when it
// changed), each with a CRC32, and a footer with the frame offset table. A
// reader that finds no footer (a crashed writer) recovers every complete
// frame by scanning. Layout in docs/PCACHE.md.
#include <array>
#include <cstdint>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::cache {

inline constexpr std::uint32_t kFormatVersion = 1;

// An extension sub-block: data a later format revision attaches to the
// header or to a frame (tear-atlas references, sound events, ...) without
// breaking older readers. A reader keeps the sub-blocks it does not interpret
// here, verbatim and in file order, so a cache can be copied losslessly; the
// writer writes them back as given. Tags are four bytes, any values.
struct ExtensionBlock {
  std::array<char, 4> tag{};
  std::vector<std::uint8_t> data;
  bool operator==(const ExtensionBlock&) const = default;
};

struct CacheHeader {
  std::uint32_t formatVersion = kFormatVersion;
  double fps = 24.0;
  int frameStart = 1;
  int frameEnd = 1;  // planned last frame (inclusive); the file may hold fewer
  int substeps = 1;
  std::uint64_t seed = 0;
  std::string sceneName;
  std::string sceneFile;     // path of the scene file the shot came from
  std::string sceneText;     // the scene file's text (renderers re-parse it)
  double sheetWidth = 0.0;   // m (0 for a pattern mesh)
  double sheetHeight = 0.0;  // m
  std::string paperName;
  double paperThickness = 0.0;  // m
  std::vector<std::string> handleNames;
  std::vector<ExtensionBlock> extensions;  // sub-blocks this version does not interpret
};

struct CameraRecord {
  Vec3 position = Vec3::Zero();
  Quat rotation = Quat::Identity();  // looks down local -Z, +Y up
  double yfov = 0.0;                 // rad
};

struct FrameRecord {
  int frame = 0;
  double time = 0.0;  // s
  // Topology (written only when it differs from the previous frame's).
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> regionOfTriangle;
  std::vector<std::uint8_t> regionTypes;  // mesh::RegionType per region id
  std::vector<Vec2> pattern;              // m
  // Geometry.
  std::vector<Vec3> positions;  // m
  // Model structure (empty until the crumpling model fills them).
  std::vector<int> singularVertices;
  std::vector<int> junctionVertices;
  std::vector<std::array<int, 2>> rulings;
  std::uint32_t tearCount = 0;  // tears started so far
  // Handles, in header.handleNames order: the constrained vertex and the
  // imported track's position at this frame's time.
  std::vector<int> handleVertices;
  std::vector<Vec3> handleTargets;
  CameraRecord camera;
  std::vector<ExtensionBlock> extensions;  // sub-blocks this version does not interpret
};

// Writes a cache. Frames are appended in order; close() writes the footer.
// The file is written in place (no temporary): the header at construction,
// then append() writes one complete frame chunk and flushes it, so a killed
// process leaves every appended frame readable.
//
// The destructor does NOT write the footer: a writer destroyed without
// close() (an exception unwinding, a crash) leaves a footer-less file that
// looks like the crashed run it is, and CacheReader recovers its complete
// frames (recovered() == true). Call close() explicitly on success, and also
// after a clean numerical failure (the cache is then valid up to the last
// good frame).
//
// append() takes the full frame; the topology (triangles, regionOfTriangle,
// regionTypes, pattern) is stored only when it differs bit for bit from the
// previous appended frame's (always for the first frame). Frame numbers must
// increase strictly (std::invalid_argument otherwise). The header's
// formatVersion is ignored: the writer always writes kFormatVersion.
// Identical input gives a byte-identical file.
// I/O failures (cannot create, cannot write) throw InputError naming the path;
// after a failed write the writer refuses further appends and close() throws.
class CacheWriter {
 public:
  // Throws InputError if the file cannot be created.
  CacheWriter(const std::string& path, const CacheHeader& header);
  ~CacheWriter();
  CacheWriter(const CacheWriter&) = delete;
  CacheWriter& operator=(const CacheWriter&) = delete;
  void append(const FrameRecord& frame);
  // Writes the footer and trailer and closes the file. A second call does
  // nothing; append() after close() throws std::logic_error.
  void close();

  // Resume (checkpoint and resume): reopens the cache at `path` that
  // an interrupted (or finished) run wrote with `header`, keeps its first
  // `keepFrames` complete frames and cuts everything after them (frames
  // written after the checkpoint, a torn last chunk, the footer), so that
  // appending the following frames writes the very bytes the uninterrupted
  // run would have. Throws InputError when the file cannot be opened or
  // written, holds fewer complete frames, or its header is not `header`'s.
  static std::unique_ptr<CacheWriter> resume(const std::string& path, const CacheHeader& header,
                                             std::size_t keepFrames);
  std::size_t framesWritten() const;

 private:
  CacheWriter();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What the reader checks of decoded data before it hands it out
// (docs/PCACHE.md "What the reader checks"): an empty string when valid,
// else the first problem, naming the block. The header: a positive finite
// fps, planned frames in order, substeps >= 1, finite non-negative sizes.
// A frame (its topology carried): sizes that agree, every index (triangles,
// regions, singular and junction vertices, rulings, handles, contacts and
// their colliders) within the frame's own counts, every real finite.
std::string validate(const CacheHeader& header);
std::string validate(const FrameRecord& frame, const CacheHeader& header);

// A problem found while reading: which frame (or -1 for header/footer).
struct CacheIssue {
  int frameIndex = -1;
  std::string message;
  std::optional<int> frame;  // the frame number, when known
};

class CacheReader {
 public:
  // Opens and indexes a cache: uses the footer when it is intact, otherwise
  // scans and keeps every complete, CRC-valid frame before the first bad one
  // (recovered() is then true). Throws InputError for a missing file or a
  // damaged header, CorruptDataError never here.
  explicit CacheReader(const std::string& path);
  ~CacheReader();
  CacheReader(CacheReader&&) noexcept;
  CacheReader& operator=(CacheReader&&) noexcept;

  const CacheHeader& header() const;
  std::size_t frameCount() const;
  bool recovered() const;
  // Issues found while opening (missing footer, truncated block, CRC mismatch).
  const std::vector<CacheIssue>& issues() const;
  // Full frame (topology carried forward from earlier frames). Throws
  // CorruptDataError naming the frame number when its CRC does not match.
  // std::out_of_range for index >= frameCount(). Thread-safe (each call
  // reads the file on its own).
  FrameRecord readFrame(std::size_t index) const;

  // Reads every indexed frame chunk and checks its CRC and structure (opening
  // with an intact footer checks none of them). One issue per bad frame,
  // naming its frame number; empty when all are good.
  std::vector<CacheIssue> verifyAll() const;
  // From the index, without reading the frame: its frame number, and the
  // index of the frame whose chunk holds its topology (itself if it has one).
  int frameNumber(std::size_t index) const;
  std::size_t topologySource(std::size_t index) const;
  const std::string& path() const;

 private:
  friend class CacheWriter;  // resume() reads the index
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::cache
