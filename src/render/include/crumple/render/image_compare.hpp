#pragma once
// Image comparison for golden tests and `crumple compare`: MAE, PSNR and
// LDR-FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for
// Alternating Images", HPG), plus a heat-map image of the differences.
//
// Inputs are ImageRGBA8 (sRGB 8-bit, straight alpha, rows top-down).
#include <vector>

#include "crumple/core/image.hpp"

namespace crumple::render {

enum class ImageMetric {
  // Mean absolute difference over all pixels and the 4 channels (R, G, B, A),
  // in 8-bit units (0 = identical, 255 = maximally different). Lower is better.
  Mae,
  // 10 log10(255^2 / MSE), MSE the mean squared difference over all pixels and
  // the 4 channels in 8-bit units; in dB, +infinity when the images are
  // identical. Higher is better.
  Psnr,
  // The mean of the LDR-FLIP error map (in [0, 1]; 0 = identical) of the two
  // images' RGB, each composited over mid grey (0.5 linear) by its alpha, at
  // kFlipPixelsPerDegree (see flipErrorMap). Lower is better.
  Flip,
};

struct ImageComparison {
  double value = 0.0;     // the chosen metric (see ImageMetric)
  double maeRgb = 0.0;    // mean |a - b| of the R, G, B channels over all pixels, 8-bit units
  double alphaIoU = 1.0;  // |both covered| / |either covered|, covered = alpha >= 128; 1 when
                          // neither image covers any pixel
  double maxAbs = 0.0;    // the largest |a - b| of any channel (R, G, B, A), 8-bit units
  // Heat map, same size as the inputs, alpha 255 (see compareImages).
  ImageRGBA8 diff;
};

// The reference implementation's default observer: a 0.7 m wide, 3840 pixel
// wide monitor seen from 0.7 m, 0.7 * 3840 / 0.7 * pi / 180 = 67.02 pixels per
// degree of visual angle.
inline constexpr double kFlipPixelsPerDegree = 0.7 * 3840.0 / 0.7 * 3.14159265358979323846 / 180.0;

// Compares a (the reference) with b (the test).
// - value, maeRgb, alphaIoU, maxAbs as documented above, whatever the metric.
// - diff: Mae and Psnr show per pixel d = the largest |a - b| over the 4
//   channels (8-bit units) at t = sqrt(min(d, 32) / 32); Flip shows the
//   pixel's FLIP error t. t goes through the heat map black (0) -> red (1/3)
//   -> yellow (2/3) -> white (1), linearly between those stops in sRGB. So a
//   single-level difference (d = 1) is a clearly visible dark red (135, 0, 0),
//   d = 8 is orange and d >= 32 is white. Every diff pixel has alpha 255.
// Throws std::invalid_argument if the sizes differ or an image is empty or
// inconsistent (pixels.size() != width * height * 4).
ImageComparison compareImages(const ImageRGBA8& a, const ImageRGBA8& b, ImageMetric metric);

// Mae and Flip pass when value <= tolerance, Psnr when value >= tolerance (so
// identical images, PSNR +infinity, always pass). A NaN value never passes.
bool passes(const ImageComparison& comparison, ImageMetric metric, double tolerance);

// The per-pixel LDR-FLIP error (row-major, top row first, values in [0, 1])
// between two same-sized images whose RGB is composited over mid grey (0.5
// linear) by alpha first. Follows the paper and NVIDIA's reference
// implementation (github.com/NVlabs/flip):
// - colour pipeline: linear RGB -> YCxCz; the contrast sensitivity filters
//   per channel; clamp to the linear RGB cube; Hunt-adjusted L*a*b*; HyAB
//   distance raised to qc = 0.7, redistributed with pc = 0.4, pt = 0.95;
// - feature pipeline: edge and point detectors on the achromatic channel,
//   feature difference raised to qf = 0.5;
// - final difference: error = colour^(1 - feature).
// Borders are clamp-to-edge. Symmetric in its arguments. Throws as
// compareImages does; also std::invalid_argument unless pixelsPerDegree > 0.
std::vector<double> flipErrorMap(const ImageRGBA8& reference, const ImageRGBA8& test,
                                 double pixelsPerDegree = kFlipPixelsPerDegree);

}  // namespace crumple::render
