#include "frame_output.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "crumple/core/error.hpp"
#include "crumple/exporters/exr.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/render/contact_sheet.hpp"
#include "crumple/render/renderer.hpp"

extern char** environ;

namespace crumple::pipeline::detail {
namespace fs = std::filesystem;

std::string frameFileName(int frame, const char* extension) {
  char name[48];
  std::snprintf(name, sizeof name, "%04d.%s", frame, extension);
  return name;
}

namespace {

// The structure view (paper Fig. 2): flat regions green, curved regions
// magenta with their rulings, singular vertices red, junction vertices
// yellow, handles black.
render::StructureOverlay structureOverlay(const cache::FrameRecord& frame) {
  const render::StructurePalette palette;
  render::StructureOverlay overlay;
  for (int region : frame.regionOfTriangle) {
    const bool curved = static_cast<std::size_t>(region) < frame.regionTypes.size() &&
                        frame.regionTypes[static_cast<std::size_t>(region)] ==
                            static_cast<std::uint8_t>(mesh::RegionType::Curved);
    overlay.triangleColors.push_back(curved ? palette.curved : palette.flat);
  }
  const auto at = [&](int v) { return frame.positions[static_cast<std::size_t>(v)]; };
  for (const auto& r : frame.rulings) overlay.lines.push_back({at(r[0]), at(r[1]), palette.ruling});
  for (int v : frame.junctionVertices) overlay.points.push_back({at(v), palette.junction});
  for (int v : frame.singularVertices) overlay.points.push_back({at(v), palette.singular});
  for (int v : frame.handleVertices)
    if (v >= 0) overlay.points.push_back({at(v), palette.handle});
  return overlay;
}

}  // namespace

// What the frames are refined with: as asked, else auto for the path
// tracer; never under the structure view (its colours are per S_P triangle).
mesh::RefineOptions refinement(const RenderSettings& settings, bool debugStructure) {
  if (debugStructure) {
    if (settings.refine && settings.refine->mode != mesh::RefineMode::Off)
      throw InputError("--refine", "the structure view shows the simulated mesh: use --refine off");
    return FrameViewBuilder::offRefinement();
  }
  if (settings.refine) return *settings.refine;
  return settings.backend == RenderSettings::Backend::Embree ? mesh::RefineOptions{}
                                                             : FrameViewBuilder::offRefinement();
}

struct FrameRenderer::Impl {
  std::string framesDir;
  bool debugStructure = false;
  RenderSettings settings;
  FrameViewBuilder views;
  std::unique_ptr<render::Renderer> renderer;

  Impl(const io::SceneSpec& scene, const std::vector<cache::ExtensionBlock>& headerBlocks,
       std::string dir, bool debug, const RenderSettings& r, std::uint64_t seed)
      : framesDir(std::move(dir)),
        debugStructure(debug),
        settings(r),
        views(scene, headerBlocks, refinement(r, debug)) {
    const bool embree = settings.backend == RenderSettings::Backend::Embree;
    if (embree && debugStructure)
      throw InputError("--debug-structure",
                       "the structure view is drawn by the osmesa backend only");
    if (!embree && !settings.aovs.empty())
      throw InputError("--aov", "AOVs are computed by the embree backend only (--backend embree)");
    // Motion blur: the path tracer's; the preview draws each frame's own positions.
    const cache::Shutter shutter = settings.shutter.value_or(views.shutter());
    if (shutter.on() && !cache::decodeShutter(headerBlocks))
      throw InputError("--shutter",
                       "the cache holds no sub-frame motion: simulate the shot with [camera] "
                       "shutter (or run/simulate --shutter) to blur it");
    views.setShutter(embree ? shutter : cache::Shutter{});
    render::RendererOptions options;
    options.width = scene.camera.width;
    options.height = scene.camera.height;
    options.samplesPerPixel = settings.samplesPerPixel;
    options.maxBounces = settings.maxBounces;
    options.seed = seed;
    renderer =
        render::makeRenderer(embree ? render::Backend::Embree : render::Backend::Osmesa, options);
  }

  void render(const cache::FrameRecord& frame) {
    const FrameView fv = views.build(frame);
    render::FrameSettings frameSettings;
    frameSettings.frame = frame.frame;
    frameSettings.aovs = settings.aovs;
    std::optional<render::StructureOverlay> overlay;
    if (debugStructure) {
      overlay = structureOverlay(frame);
      frameSettings.overlay = &*overlay;
    }
    const render::RenderedImage image =
        renderer->render(fv.scene, fv.sheet, frameSettings, settings.pass);
    const fs::path dir(framesDir);
    if (const render::AovImage* aovs = image.aovs())
      exporters::writeExr((dir / frameFileName(frame.frame, "exr")).string(), image.linear(),
                          *aovs);
    else if (settings.exr)
      exporters::writeExr((dir / frameFileName(frame.frame, "exr")).string(), image.linear());
    if (settings.png)
      exporters::writePng((dir / frameFileName(frame.frame)).string(), image.srgb8());
  }
};

FrameRenderer::FrameRenderer(const io::SceneSpec& scene,
                             const std::vector<cache::ExtensionBlock>& headerBlocks,
                             std::string framesDir, bool debugStructure,
                             const RenderSettings& settings, std::uint64_t seed)
    : impl_(std::make_unique<Impl>(scene, headerBlocks, std::move(framesDir), debugStructure,
                                   settings, seed)) {}
FrameRenderer::~FrameRenderer() = default;
void FrameRenderer::render(const cache::FrameRecord& frame) { impl_->render(frame); }

std::vector<int> writeContactSheet(const std::string& framesDir, int first, int last,
                                   const std::string& path) {
  constexpr int kMaxCells = 36;
  const int n = last - first + 1;
  std::vector<int> picked;
  if (n <= kMaxCells) {
    for (int f = first; f <= last; ++f) picked.push_back(f);
  } else {
    for (int i = 0; i < kMaxCells; ++i)
      picked.push_back(first + static_cast<int>(std::lround(static_cast<double>(i) * (n - 1) /
                                                            (kMaxCells - 1))));
  }
  std::vector<std::pair<int, ImageRGBA8>> frames;
  for (const int f : picked)
    frames.emplace_back(f, exporters::readPng((fs::path(framesDir) / frameFileName(f)).string()));
  const int cellWidth = std::min(320, frames.front().second.width);
  exporters::writePng(path, render::makeContactSheet(frames, 0, cellWidth));
  return picked;
}

namespace {

// The first executable `name` on PATH, or empty.
std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const fs::path candidate = fs::path(dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return {};
}

// Runs argv[0] with its arguments (no shell) and returns its exit status, or
// -1 when it could not be started.
int runProcess(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (::posix_spawn(&pid, argv[0].c_str(), nullptr, nullptr, args.data(), environ) != 0) return -1;
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

bool makeMovie(const std::string& framesDir, int first, int last, double fps,
               const std::string& sound, const std::string& path, std::string& note) {
  const std::string ffmpeg = findOnPath("ffmpeg");
  if (ffmpeg.empty()) {
    note =
        "--movie: ffmpeg is not installed (Debian: apt-get install ffmpeg); the frames are "
        "written, no movie";
    return false;
  }
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.6g", fps);
  const std::string tmp = path + ".tmp.mp4";
  std::vector<std::string> argv = {ffmpeg,
                                   "-nostdin",
                                   "-loglevel",
                                   "error",
                                   "-y",
                                   "-framerate",
                                   rate,
                                   "-start_number",
                                   std::to_string(first),
                                   "-i",
                                   (fs::path(framesDir) / "%04d.png").string()};
  std::error_code ec;
  const bool withSound = fs::is_regular_file(sound, ec);
  if (withSound) argv.insert(argv.end(), {"-i", sound});
  argv.insert(argv.end(), {"-frames:v", std::to_string(last - first + 1)});
  if (withSound) argv.insert(argv.end(), {"-c:a", "aac", "-b:a", "192k", "-shortest"});
  // Even dimensions for yuv420p; transparent pixels over black.
  argv.insert(argv.end(), {"-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt",
                           "yuv420p", "-crf", "18", "-movflags", "+faststart", tmp});
  const int status = runProcess(argv);
  if (status != 0) {
    fs::remove(tmp, ec);
    note = "--movie: ffmpeg failed (exit status " + std::to_string(status) + "); no movie written";
    return false;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    note = "--movie: cannot write " + path;
    return false;
  }
  note =
      withSound ? "" : "--movie: no soundtrack in this shot yet (sound.wav); the movie is silent";
  return true;
}

}  // namespace crumple::pipeline::detail
