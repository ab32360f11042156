// `crumple compare`: two images for golden-image tests, or two caches by
// their shapes.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/exr.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/pipeline/shape_compare.hpp"
#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/image_compare.hpp"

namespace crumple::cli {

namespace {

// Reads a PNG, or an EXR converted to 8-bit sRGB (straight alpha).
ImageRGBA8 readImage(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".exr" || ext == ".EXR")
    return render::toSrgb8(exporters::readExr(path), Vec3::Zero());
  return exporters::readPng(path);
}

// `crumple compare A.pcache B.pcache`: the two shots' shapes frame by frame
// (pipeline/shape_compare.hpp).
int compareShapesCommand(const Args& a) {
  if (a.shapeTolerance && !(std::isfinite(*a.shapeTolerance) && *a.shapeTolerance >= 0.0))
    throw InputError("--shape-tolerance", "must be a finite distance >= 0 (m)");
  const cache::CacheReader ra(a.imageA);
  const cache::CacheReader rb(a.imageB);
  std::vector<pipeline::ShapeDistance> d = pipeline::compareShapes(ra, rb);
  if (!a.frames.empty()) {
    const pipeline::FrameRange range = pipeline::parseFrameRange(a.frames);
    std::erase_if(d, [&](const auto& x) { return x.frame < range.first || x.frame > range.last; });
    if (d.empty()) throw InputError("--frames", "'" + a.frames + "': no frame both caches hold");
  }
  double worst = 0.0;
  int worstFrame = d.front().frame;
  for (const auto& x : d)
    if (x.mean > worst) {
      worst = x.mean;
      worstFrame = x.frame;
    }
  const bool ok = !a.shapeTolerance || worst <= *a.shapeTolerance;
  if (a.json) {
    std::printf("{\"frames\": [");
    for (std::size_t i = 0; i < d.size(); ++i)
      std::printf(
          "%s{\"frame\": %d, \"mean\": %.9g, \"max\": %.9g, \"outside\": %zu, "
          "\"singular_vertices\": %zu}",
          i > 0 ? ", " : "", d[i].frame, d[i].mean, d[i].max, d[i].outside, d[i].singularVertices);
    std::printf("], \"worst_mean\": %.9g, \"worst_frame\": %d}\n", worst, worstFrame);
  } else {
    std::printf(" frame    mean[m]     max[m]  outside  singular(A)\n");
    for (const auto& x : d)
      std::printf("%6d %10.4g %10.4g %8zu %12zu\n", x.frame, x.mean, x.max, x.outside,
                  x.singularVertices);
    std::printf("%s largest mean distance %.4g m at frame %d over %zu frames", ok ? "PASS" : "FAIL",
                worst, worstFrame, d.size());
    if (a.shapeTolerance) std::printf(" (tolerance %.4g m)", *a.shapeTolerance);
    std::printf("\n");
  }
  return ok ? 0 : 1;
}

bool isCache(const std::string& path) {
  return std::filesystem::path(path).extension() == ".pcache";
}

}  // namespace

int compareCommand(const Args& a) {
  if (isCache(a.imageA) || isCache(a.imageB)) {
    if (!isCache(a.imageA) || !isCache(a.imageB))
      throw InputError(a.imageB, "compare takes two images or two .pcache caches");
    return compareShapesCommand(a);
  }
  render::ImageMetric metric = render::ImageMetric::Flip;
  if (a.metric == "mae")
    metric = render::ImageMetric::Mae;
  else if (a.metric == "psnr")
    metric = render::ImageMetric::Psnr;
  else if (a.metric != "flip")
    throw InputError("--metric", "'" + a.metric + "' is not a metric (mae, psnr or flip)");
  if (!std::isfinite(a.tolerance) || a.tolerance < 0.0)
    throw InputError("--tolerance", "must be a finite number >= 0");
  const ImageRGBA8 ia = readImage(a.imageA);
  const ImageRGBA8 ib = readImage(a.imageB);
  if (ia.width != ib.width || ia.height != ib.height)
    throw InputError(a.imageB, "is " + std::to_string(ib.width) + "x" + std::to_string(ib.height) +
                                   ", " + a.imageA + " is " + std::to_string(ia.width) + "x" +
                                   std::to_string(ia.height));
  const auto c = render::compareImages(ia, ib, metric);
  const std::string diffPath =
      !a.diff.empty() ? a.diff
                      : (std::filesystem::path(a.imageB).parent_path() /
                         (std::filesystem::path(a.imageB).stem().string() + ".diff.png"))
                            .string();
  exporters::writePng(diffPath, c.diff);
  const bool ok = render::passes(c, metric, a.tolerance);
  std::printf(
      "%s %s: %.6g (tolerance %.6g, %s); mean |RGB difference| %.4g/255, alpha IoU %.6f\n"
      "  diff: %s\n",
      ok ? "PASS" : "FAIL", a.metric.c_str(), c.value, a.tolerance,
      metric == render::ImageMetric::Psnr ? "higher is better" : "lower is better", c.maeRgb,
      c.alphaIoU, diffPath.c_str());
  return ok ? 0 : 1;
}

}  // namespace crumple::cli
