#include "checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"

namespace crumple::pipeline {
namespace {

constexpr std::uint32_t kCheckpointVersion = 7;
constexpr char kMagic[9] = "CRUMPCKP";

std::uint64_t sceneHash(const io::SceneSpec& scene) {
  return fnv1a64(scene.sourceText.data(), scene.sourceText.size());
}

// Checks the inputs a checkpoint recorded against the shot's now: the same
// files (by their part in the shot), each with the same size and hash.
void checkInputs(StateReader& r, const std::string& path, const std::vector<ShotInput>& now) {
  const std::size_t n = r.count(8 + 8 + 8 + 8);
  bool sameFiles = n == now.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::string what = r.str();
    (void)r.str();  // the path it had then: the file may have moved since, its bytes count
    const std::uint64_t size = r.u64(), hash = r.u64();
    if (k >= now.size() || now[k].what != what) {
      sameFiles = false;
      continue;
    }
    if (size != now[k].size || hash != now[k].hash)
      throw InputError(path, what + " " + now[k].path +
                                 " changed since the checkpoint was written: cannot resume");
  }
  if (!sameFiles)
    throw InputError(path, "the files the scene reads changed since the checkpoint was written (" +
                               std::to_string(n) + " then, " + std::to_string(now.size()) +
                               " now): cannot resume");
}

}  // namespace

void writeCheckpointHead(StateWriter& w, const io::SceneSpec& scene,
                         const std::vector<ShotInput>& inputs, std::uint64_t seed, int lastFrame,
                         int frame, std::size_t cachedFrames) {
  w.tag("CKPT");
  w.u32(kCheckpointVersion);
  w.u64(sceneHash(scene));
  w.u64(scene.sourceText.size());
  w.count(inputs.size());
  for (const ShotInput& input : inputs) {
    w.str(input.what);
    w.str(input.path);
    w.u64(input.size);
    w.u64(input.hash);
  }
  w.u64(seed);
  w.i32(scene.frameStart);
  w.i32(lastFrame);
  w.i32(frame);
  w.count(cachedFrames);
}

void writeCheckpointFile(const std::string& path, const StateWriter& w) {
  const std::string tmp = path + ".tmp";
  const auto& data = w.data();
  const std::uint32_t crc = crc32(data.data(), data.size());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr)
    throw InputError(tmp, std::string("cannot write the checkpoint: ") + std::strerror(errno));
  std::uint8_t tail[4];
  for (int k = 0; k < 4; ++k) tail[k] = static_cast<std::uint8_t>(crc >> (8 * k));
  const bool ok = std::fwrite(kMagic, 1, 8, f) == 8 &&
                  std::fwrite(data.data(), 1, data.size(), f) == data.size() &&
                  std::fwrite(tail, 1, 4, f) == 4 && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  const int err = errno;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw InputError(tmp, std::string("cannot write the checkpoint: ") + std::strerror(err));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InputError(path, "cannot write the checkpoint: " + ec.message());
}

Checkpoint readCheckpoint(const std::string& path, const io::SceneSpec& scene,
                          const std::vector<ShotInput>& inputs, std::uint64_t seed, int lastFrame) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path, "no checkpoint to resume from (run with --checkpoint-every N first)");
  std::vector<std::uint8_t> file((std::istreambuf_iterator<char>(in)), {});
  if (file.size() < 12 || std::memcmp(file.data(), kMagic, 8) != 0)
    throw InputError(path, "not a crumple checkpoint");
  std::uint32_t stored = 0;
  for (int k = 0; k < 4; ++k)
    stored |= static_cast<std::uint32_t>(file[file.size() - 4 + static_cast<std::size_t>(k)])
              << (8 * k);
  auto bytes = std::make_shared<std::vector<std::uint8_t>>(file.begin() + 8, file.end() - 4);
  if (crc32(bytes->data(), bytes->size()) != stored)
    throw InputError(path, "the checkpoint is damaged (CRC mismatch)");
  Checkpoint c;
  c.bytes = bytes;
  c.state = std::make_unique<StateReader>(*bytes, path);
  StateReader& r = *c.state;
  try {
    r.tag("CKPT");
    if (const auto v = r.u32(); v != kCheckpointVersion)
      throw InputError(path, std::string("checkpoint version ") + std::to_string(v) +
                                 ", this crumple reads " + std::to_string(kCheckpointVersion));
    const std::uint64_t hash = r.u64();
    const std::uint64_t length = r.u64();
    if (hash != sceneHash(scene) || length != scene.sourceText.size())
      throw InputError(path, "belongs to another scene (" + scene.file +
                                 " changed since it was written): cannot resume");
    checkInputs(r, path, inputs);
    if (r.u64() != seed) throw InputError(path, "was written with another seed: cannot resume");
    const int first = r.i32(), last = r.i32();
    if (first != scene.frameStart || last != lastFrame)
      throw InputError(path, std::string("covers frames ") + std::to_string(first) + "-" +
                                 std::to_string(last) + ", this run " +
                                 std::to_string(scene.frameStart) + "-" +
                                 std::to_string(lastFrame) + ": cannot resume");
    c.frame = r.i32();
    c.cachedFrames = r.count(0);
    if (c.frame < first || c.frame > last)
      r.fail(std::string("frame ") + std::to_string(c.frame) + " out of range");
  } catch (const CorruptDataError& e) {
    throw InputError(path, e.what());
  }
  return c;
}

void saveReport(StateWriter& w, const ShotReport& r) {
  w.tag("REPT");
  w.i32(r.framesSimulated);
  w.i32(r.framesRendered);
  w.i64(static_cast<std::int64_t>(r.vertices));
  w.i64(static_cast<std::int64_t>(r.triangles));
  w.i64(static_cast<std::int64_t>(r.maxTriangles));
  w.i32(r.singularVertices);
  w.i32(r.interiorSingularVertices);
  w.i64(r.newtonIterations);
  w.i64(r.substeps);
  w.i64(r.halvings);
  w.i64(r.elasticRetries);
  w.i64(r.strainLimitRuns);
  w.i64(r.strainLimitCarried);
  w.i64(r.elasticHeldStill);
  w.i32(r.elasticHeldFirst);
  w.i32(r.elasticHeldLast);
  w.i32(r.lagFrames);
  w.f64(r.maxHandleLag);
  w.i32(r.maxHandleLagFrame);
  w.i32(r.maxHandleLagVertex);
  w.f64(r.contactMs);
  w.f64(r.selfContactMs);
  w.f64(r.airMs);
  w.i64(r.selfContactSteps);
  w.f64(r.maxContactDepth);
  w.i32(r.maxContactDepthFrame);
  w.i64(r.contactSamples);
  for (long n : r.soundEvents) w.i64(n);
  w.f64(r.soundResonatorMs);
  w.f64(r.maxHandleError);
  w.f64(r.maxStrain);
  w.f64(r.meanCMean);
  w.f64(r.maxCMean);
  w.i32(r.maxCMeanFrame);
  w.f64(r.maxNComp);
  w.count(r.handleLags.size());
  for (const auto& h : r.handleLags) {
    w.str(h.name);
    w.i32(h.frames);
    w.i32(h.firstFrame);
    w.f64(h.max);
    w.i32(h.maxFrame);
  }
  w.count(r.stages.size());
  for (const auto& [name, cost] : r.stages) {
    w.str(name);
    w.f64(cost.totalMs);
    w.i64(cost.frames);
  }
  for (const auto& span : {r.newtonRetried, r.selfContactDropped}) {
    w.i32(span.first);
    w.i32(span.last);
  }
  w.count(r.beyondReach.size());
  for (const auto& [handle, span] : r.beyondReach) {
    w.i64(static_cast<std::int64_t>(handle));
    w.i32(span.first);
    w.i32(span.last);
    w.f64(span.most);
  }
}

void restoreReport(StateReader& in, ShotReport& r, std::size_t handles) {
  in.tag("REPT");
  r.framesSimulated = in.i32();
  r.framesRendered = in.i32();
  const std::int64_t vertices = in.i64(), triangles = in.i64(), maxTriangles = in.i64();
  if (r.framesSimulated < 0 || r.framesRendered < 0 || vertices < 0 || triangles < 0 ||
      maxTriangles < 0)
    in.fail("the frame or mesh counts are out of range");
  r.vertices = static_cast<std::size_t>(vertices);
  r.triangles = static_cast<std::size_t>(triangles);
  r.maxTriangles = static_cast<std::size_t>(maxTriangles);
  r.singularVertices = in.i32();
  r.interiorSingularVertices = in.i32();
  r.newtonIterations = in.i64();
  r.substeps = in.i64();
  r.halvings = in.i64();
  r.elasticRetries = in.i64();
  r.strainLimitRuns = in.i64();
  r.strainLimitCarried = in.i64();
  r.elasticHeldStill = in.i64();
  r.elasticHeldFirst = in.i32();
  r.elasticHeldLast = in.i32();
  if (r.elasticHeldStill < 0 || r.elasticHeldLast < r.elasticHeldFirst)
    in.fail("the held-still steps' record is out of range");
  r.lagFrames = in.i32();
  r.maxHandleLag = in.f64();
  r.maxHandleLagFrame = in.i32();
  r.maxHandleLagVertex = in.i32();
  r.contactMs = in.f64();
  r.selfContactMs = in.f64();
  r.airMs = in.f64();
  r.selfContactSteps = in.i64();
  r.maxContactDepth = in.f64();
  r.maxContactDepthFrame = in.i32();
  r.contactSamples = in.i64();
  for (long& n : r.soundEvents) n = in.i64();
  r.soundResonatorMs = in.f64();
  r.maxHandleError = in.f64();
  r.maxStrain = in.f64();
  r.meanCMean = in.f64();
  r.maxCMean = in.f64();
  r.maxCMeanFrame = in.i32();
  r.maxNComp = in.f64();
  r.handleLags.resize(in.count(24));
  for (auto& h : r.handleLags) {
    h.name = in.str();
    h.frames = in.i32();
    h.firstFrame = in.i32();
    h.max = in.f64();
    h.maxFrame = in.i32();
    if (h.frames < 0 || !std::isfinite(h.max) || h.max < 0.0)
      in.fail("a handle's lag record is out of range");
  }
  r.stages.clear();
  const std::size_t n = in.count(24);
  for (std::size_t k = 0; k < n; ++k) {
    const std::string name = in.str();
    StageCost& c = r.stages[name];
    c.totalMs = in.f64();
    c.frames = in.i64();
  }
  for (ShotReport::FrameSpan* span : {&r.newtonRetried, &r.selfContactDropped}) {
    span->first = in.i32();
    span->last = in.i32();
    if (span->last < span->first) in.fail("a frame span of the warnings is out of range");
  }
  r.beyondReach.clear();
  const std::size_t reaches = in.count(8 + 4 + 4 + 8);
  for (std::size_t k = 0; k < reaches; ++k) {
    const std::int64_t handle = in.i64();
    ShotReport::BeyondReach span;
    span.first = in.i32();
    span.last = in.i32();
    span.most = in.f64();
    if (handle < 0 || handle >= static_cast<std::int64_t>(handles) || span.last < span.first ||
        !(span.most >= 0.0) || !std::isfinite(span.most))
      in.fail("a handle's beyond-reach record is out of range");
    r.beyondReach[static_cast<std::size_t>(handle)] = span;
  }
}

void saveTearingReport(StateWriter& w, const ShotReport& r) {
  w.tag("TRPT");
  w.count(r.tearAdvances.size());
  for (const auto& a : r.tearAdvances) {
    w.i32(a.frame);
    const tear::TearEvent& e = a.event;
    w.i32(e.tear);
    w.boolean(e.started);
    w.u8(static_cast<std::uint8_t>(e.kind));
    w.i32(e.vertex);
    w.f64(e.energyRelease);
    w.f64(e.fractureEnergy);
    w.vec2(e.from);
    w.vec2(e.to);
    w.boolean(e.separated);
  }
  w.i32(r.firstTearFrame);
  w.i32(r.tearHandoverFrame);
  w.i32(r.tearGeometricCuts);
  w.i32(r.tearRegionsFlattened);
  w.f64(r.tearMs);
  w.f64(r.tearBakeMs);
  w.count(r.notes.size());
  for (const auto& n : r.notes) w.str(n);
}

void restoreTearingReport(StateReader& in, ShotReport& r) {
  in.tag("TRPT");
  r.tearAdvances.resize(in.count(60));
  for (auto& a : r.tearAdvances) {
    a.frame = in.i32();
    tear::TearEvent& e = a.event;
    e.tear = in.i32();
    e.started = in.boolean();
    const std::uint8_t kind = in.u8();
    if (kind > static_cast<std::uint8_t>(tear::CandidateKind::InwardCorner))
      in.fail("a tear advance's kind of " + std::to_string(kind));
    e.kind = static_cast<tear::CandidateKind>(kind);
    e.vertex = in.i32();
    e.energyRelease = in.f64();
    e.fractureEnergy = in.f64();
    e.from = in.vec2();
    e.to = in.vec2();
    e.separated = in.boolean();
  }
  r.firstTearFrame = in.i32();
  r.tearHandoverFrame = in.i32();
  r.tearGeometricCuts = in.i32();
  r.tearRegionsFlattened = in.i32();
  r.tearMs = in.f64();
  r.tearBakeMs = in.f64();
  r.notes.resize(in.count(8));
  for (auto& n : r.notes) n = in.str();
}

void saveBlock(StateWriter& w, const cache::ExtensionBlock& b) {
  for (char c : b.tag) w.u8(static_cast<std::uint8_t>(c));
  w.count(b.data.size());
  for (std::uint8_t x : b.data) w.u8(x);
}

cache::ExtensionBlock restoreBlock(StateReader& in) {
  cache::ExtensionBlock b;
  for (char& c : b.tag) c = static_cast<char>(in.u8());
  b.data.resize(in.count(1));
  for (std::uint8_t& x : b.data) x = in.u8();
  return b;
}

}  // namespace crumple::pipeline
