// The OSMesa preview's cost per frame at production resolution
// ("median time for one 1280x720 frame of the largest sample, under 50 ms").
//
//   bench_preview [CACHE ...] [--width 1280] [--height 720] [--runs 15]
//
// Each CACHE (default: the golden inputs of every sample,
// tests/golden/inputs/*.pcache: one frame each) is rendered `runs` times with
// one renderer after a warm-up frame (shader compilation); prints the median,
// the fastest and the slowest frame, with and without the PNG encoding that
// `crumple render` adds.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/render/osmesa_renderer.hpp"

namespace {

using namespace crumple;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  int width = 1280, height = 720, runs = 15;
  std::vector<std::string> caches;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--width" || a == "--height" || a == "--runs") && i + 1 < argc) {
      const int v = std::atoi(argv[++i]);
      (a == "--width" ? width : a == "--height" ? height : runs) = v;
    } else if (a == "--help" || a == "-h") {
      std::printf("usage: bench_preview [CACHE ...] [--width W] [--height H] [--runs N]\n");
      return 0;
    } else {
      caches.push_back(a);
    }
  }
  if (width < 1 || height < 1 || runs < 1) {
    std::fprintf(stderr, "bench_preview: width, height and runs must be >= 1\n");
    return 2;
  }
  if (caches.empty()) {
    for (const auto& e :
         fs::directory_iterator(std::string(CRUMPLE_SOURCE_DIR) + "/tests/golden/inputs"))
      if (e.path().extension() == ".pcache") caches.push_back(e.path().string());
    std::sort(caches.begin(), caches.end());
  }
  render::OsmesaRenderer renderer(width, height);
  std::printf("%-22s %9s %8s %8s %8s %10s\n", "cache (frame)", "triangles", "median", "min", "max",
              "+png med");
  for (const auto& path : caches) {
    try {
      const cache::CacheReader reader(path);
      const auto& header = reader.header();
      std::string dir = fs::path(header.sceneFile).parent_path().string();
      const std::string stem = fs::path(path).stem().string();
      // Golden inputs resolve their scene's files (textures) in samples/<name>.
      if (fs::exists(std::string(CRUMPLE_SOURCE_DIR) + "/samples/" + stem))
        dir = std::string(CRUMPLE_SOURCE_DIR) + "/samples/" + stem;
      io::SceneSpec scene = io::parseScene(header.sceneText, path, dir, true);
      scene.camera.width = width;
      scene.camera.height = height;
      const auto frame = reader.readFrame(reader.frameCount() - 1);
      const pipeline::FrameViewBuilder views(scene, header.extensions);
      const auto fv = views.build(frame);
      (void)renderer.render(fv.scene, fv.sheet);  // warm-up: shader compilation
      std::vector<double> ms, msPng;
      const std::string png = (fs::temp_directory_path() / "bench_preview.png").string();
      for (int r = 0; r < runs; ++r) {
        const auto t0 = Clock::now();
        const ImageRGBA8 img = renderer.render(fv.scene, fv.sheet);
        ms.push_back(msSince(t0));
        exporters::writePng(png, img);
        msPng.push_back(msSince(t0));
      }
      fs::remove(png);
      const std::string label = stem + " (" + std::to_string(frame.frame) + ")";
      std::printf("%-22s %9zu %8.2f %8.2f %8.2f %10.2f\n", label.c_str(), fv.sheet.triangles.size(),
                  median(ms), *std::min_element(ms.begin(), ms.end()),
                  *std::max_element(ms.begin(), ms.end()), median(msPng));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_preview: %s: %s\n", path.c_str(), e.what());
      return 1;
    }
  }
  std::printf("(%dx%d, %d runs each, ms per frame; one OSMesa renderer, LP_NUM_THREADS=%s)\n",
              width, height, runs,
              std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : "default");
  return 0;
}
