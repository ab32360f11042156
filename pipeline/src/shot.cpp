#include "crumple/pipeline/shot.hpp"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "crumple/core/error.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "frame_output.hpp"
#include "shot_detail.hpp"
#include "shot_runner.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
}  // namespace

void detail::prepareOutputDir(const std::string& dir, const std::string& what) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir, "cannot create the " + what + " folder: " + ec.message());
  const fs::path probe = fs::path(dir) / ".crumple-write-probe";
  {
    std::ofstream out(probe);
    if (!out) throw InputError(dir, "the " + what + " folder is not writable");
  }
  fs::remove(probe, ec);
}

void detail::finishFrames(const std::string& framesDir, const FrameRange& range, double fps,
                          const std::string& shotDir, const RenderSettings& settings,
                          std::string& contactSheetPath, std::string& moviePath,
                          std::vector<std::string>& notes) {
  const fs::path dir = shotDir.empty() ? fs::path(".") : fs::path(shotDir);
  if (settings.contactSheet) {
    contactSheetPath = (dir / "contact_sheet.png").string();
    (void)writeContactSheet(framesDir, range.first, range.last, contactSheetPath);
  }
  if (settings.movie) {
    std::string note;
    const std::string movie = (dir / "preview.mp4").string();
    if (makeMovie(framesDir, range.first, range.last, fps, (dir / "sound.wav").string(), movie,
                  note))
      moviePath = movie;
    if (!note.empty()) notes.push_back(note);
  }
}

void detail::writeTextAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  bool written = false;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    written = static_cast<bool>(out);
  }
  std::error_code ec;
  if (written) fs::rename(tmp, path, ec);
  if (!written || ec) {
    fs::remove(tmp, ec);  // a full disk leaves no temporary behind
    throw InputError(path, "cannot write");
  }
}

FrameRange parseFrameRange(const std::string& text) {
  // "A-B" or "A", A and B integers (A may be negative: "-5--2" is -5 to -2).
  const auto bad = [&] { return InputError("--frames", "expected A-B or A, got '" + text + "'"); };
  const auto parseInt = [&](std::string_view s) {
    int value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) throw bad();
    return value;
  };
  const std::string_view all(text);
  const auto dash = all.find('-', 1);  // a leading '-' is a sign
  FrameRange r;
  r.first = parseInt(all.substr(0, dash));
  r.last = dash == std::string_view::npos ? r.first : parseInt(all.substr(dash + 1));
  if (r.last < r.first) throw InputError("--frames", "range " + text + " ends before it starts");
  return r;
}

ShotReport runShot(const io::SceneSpec& scene, const ShotOptions& options) {
  ShotRunner runner(scene, options);
  return runner.run();
}

RenderReport renderCache(const std::string& cachePath, const RenderOptions& options) {
  const cache::CacheReader reader(cachePath);
  if (reader.frameCount() == 0) throw InputError(cachePath, "the cache holds no frames");
  const auto& header = reader.header();
  const io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile + " (in " + cachePath + ")",
                     fs::path(header.sceneFile).parent_path().string(),
                     /*checkFiles=*/false);
  RenderReport report;
  if (std::string note = recoveredNote(reader); !note.empty()) {
    if (options.log) std::fprintf(options.log, "crumple render: note: %s\n", note.c_str());
    report.notes.push_back(std::move(note));
  }
  report.framesDir = !options.framesDir.empty()
                         ? options.framesDir
                         : (fs::path(cachePath).parent_path() / "frames").string();
  const int firstCached = reader.readFrame(0).frame;
  const int lastCached = firstCached + static_cast<int>(reader.frameCount()) - 1;
  FrameRange range{firstCached, lastCached};
  if (options.frames) {
    range = *options.frames;
    if (range.first < firstCached || range.last > lastCached)
      throw InputError(
          cachePath, "--frames " + std::to_string(range.first) + "-" + std::to_string(range.last) +
                         " is outside the cached frames " + std::to_string(firstCached) + "-" +
                         std::to_string(lastCached));
  }
  if ((options.rendering.contactSheet || options.rendering.movie) && !options.rendering.png)
    throw InputError("--contact-sheet/--movie", "need the PNG frames (drop --no-png)");
  detail::prepareOutputDir(report.framesDir, "frames");
  const OutputLock lock(report.framesDir,
                        options.frames ? OutputLock::Mode::Shared : OutputLock::Mode::Exclusive);
  detail::FrameRenderer renderer(scene, header.extensions, report.framesDir, options.debugStructure,
                                 options.rendering, header.seed);
  Progress progress(std::string("crumple render (") + backendName(options.rendering.backend) + ")",
                    range.last - range.first + 1, options.log, options.interactive);
  for (int f = range.first; f <= range.last; ++f) {
    const auto frame = reader.readFrame(static_cast<std::size_t>(f - firstCached));
    const auto start = Clock::now();
    renderer.render(frame);
    report.cost.totalMs += msSince(start);
    report.cost.frames += 1;
    ++report.framesRendered;
    progress.update(f - range.first + 1);
  }
  progress.finish();
  detail::finishFrames(report.framesDir, range, scene.fps,
                       fs::path(cachePath).parent_path().string(), options.rendering,
                       report.contactSheetPath, report.moviePath, report.notes);
  return report;
}

const char* backendName(RenderSettings::Backend backend) {
  return backend == RenderSettings::Backend::Embree ? "embree" : "osmesa";
}

}  // namespace crumple::pipeline
