// Image metrics: MAE, PSNR and LDR-FLIP (Andersson, Nilsson, Akenine-Moller,
// Oskarsson, Astrom, Fairchild 2020, "FLIP: A Difference Evaluator for
// Alternating Images", Proc. ACM CGIT 3(2), HPG). The FLIP code follows the
// paper's colour and feature pipelines with the constants of NVIDIA's
// reference implementation (github.com/NVlabs/flip), in double precision (the
// reference computes in float; means agree to ~1e-5).
#include "crumple/render/image_compare.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "crumple/render/view.hpp"

namespace crumple::render {
namespace {

constexpr double kPi = 3.14159265358979323846;

// FLIP constants (as in the paper and the reference implementation).
constexpr double kQc = 0.7;    // exponent of the HyAB colour difference
constexpr double kPc = 0.4;    // cmax fraction at which the redistribution changes slope
constexpr double kPt = 0.95;   // error assigned to pc * cmax
constexpr double kQf = 0.5;    // exponent of the feature difference
constexpr double kGw = 0.082;  // peak-to-trough width of the edge detector, degrees
// Contrast sensitivity functions as sums of Gaussians a sqrt(pi / b) exp(-pi^2
// r^2 / b) (r in degrees): achromatic, red-green, blue-yellow (two terms).
constexpr double kA1[3] = {1.0, 1.0, 34.1};
constexpr double kB1[3] = {0.0047, 0.0053, 0.04};
constexpr double kA2[3] = {0.0, 0.0, 13.5};
constexpr double kB2[3] = {1.0e-5, 1.0e-5, 0.025};
// D65 white point (XYZ) and its inverse, as in the reference.
constexpr double kWhite[3] = {0.950428545, 1.0, 1.088900371};
constexpr double kInvWhite[3] = {1.052156925, 1.0, 0.918357670};

using Color = std::array<double, 3>;

// Linear sRGB -> CIE XYZ (D65), the reference's exact rational matrix.
Color linearRgbToXyz(const Color& c) {
  return {(10135552.0 / 24577794.0) * c[0] + (8788810.0 / 24577794.0) * c[1] +
              (4435075.0 / 24577794.0) * c[2],
          (2613072.0 / 12288897.0) * c[0] + (8788810.0 / 12288897.0) * c[1] +
              (887015.0 / 12288897.0) * c[2],
          (1425312.0 / 73733382.0) * c[0] + (8788810.0 / 73733382.0) * c[1] +
              (70074185.0 / 73733382.0) * c[2]};
}

// CIE XYZ (D65) -> linear sRGB (the inverse of linearRgbToXyz).
Color xyzToLinearRgb(const Color& c) {
  return {3.241003275 * c[0] - 1.537398934 * c[1] - 0.498615861 * c[2],
          -0.969224334 * c[0] + 1.875930071 * c[1] + 0.041554224 * c[2],
          0.055639423 * c[0] - 0.204011202 * c[1] + 1.057148933 * c[2]};
}

// XYZ -> YCxCz, the linearised L*a*b* opponent space of the colour pipeline.
Color xyzToYCxCz(const Color& c) {
  const double x = c[0] * kInvWhite[0], y = c[1] * kInvWhite[1], z = c[2] * kInvWhite[2];
  return {116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)};
}

// YCxCz -> XYZ (the inverse of xyzToYCxCz).
Color yCxCzToXyz(const Color& c) {
  const double y = (c[0] + 16.0) / 116.0;
  return {(y + c[1] / 500.0) * kWhite[0], y * kWhite[1], (y - c[2] / 200.0) * kWhite[2]};
}

// XYZ -> CIE L*a*b* (D65).
Color xyzToLab(const Color& c) {
  constexpr double delta = 6.0 / 29.0;
  constexpr double deltaCube = delta * delta * delta;
  constexpr double factor = 1.0 / (3.0 * delta * delta);
  Color f;
  for (int k = 0; k < 3; ++k) {
    const double v = c[k] * kInvWhite[k];
    f[k] = v > deltaCube ? std::cbrt(v) : factor * v + 4.0 / 29.0;
  }
  return {116.0 * f[1] - 16.0, 500.0 * (f[0] - f[1]), 200.0 * (f[1] - f[2])};
}

// Hunt adjustment of L*a*b* (colour pipeline, "perceptually uniform colour
// space"): chroma scaled by 0.01 L*, so dark colours differ less.
Color huntAdjust(const Color& lab) {
  return {lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]};
}

// HyAB distance (colour pipeline, "colour metric"): |dL| + ||(da, db)||.
double hyab(const Color& p, const Color& q) {
  return std::abs(p[0] - q[0]) + std::hypot(p[1] - q[1], p[2] - q[2]);
}

// cmax = HyAB(green, blue)^qc in Hunt-adjusted L*a*b*: the largest
// difference between two colours of the linear RGB cube.
double flipCmax() {
  const Color green = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 1.0, 0.0})));
  const Color blue = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 0.0, 1.0})));
  return std::pow(hyab(green, blue), kQc);
}

// 8-bit sRGB -> linear, tabulated.
const std::array<double, 256>& srgbTable() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i)
      t[static_cast<std::size_t>(i)] = srgb8ToLinear(static_cast<std::uint8_t>(i));
    return t;
  }();
  return table;
}

// A single-channel image, row-major.
struct Plane {
  int width = 0;
  int height = 0;
  std::vector<double> v;
  Plane(int w, int h) : width(w), height(h), v(static_cast<std::size_t>(w) * h, 0.0) {}
  double& operator()(int x, int y) { return v[static_cast<std::size_t>(y) * width + x]; }
  double operator()(int x, int y) const { return v[static_cast<std::size_t>(y) * width + x]; }
};

// Convolves rows (horizontal) and then columns (vertical) with 1D kernels of
// odd length, clamping coordinates to the image (the reference's borders).
Plane convolveSeparable(const Plane& in, const std::vector<double>& kx,
                        const std::vector<double>& ky) {
  const int w = in.width, h = in.height;
  const int rx = static_cast<int>(kx.size() / 2), ry = static_cast<int>(ky.size() / 2);
  Plane tmp(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int i = -rx; i <= rx; ++i)
        s += kx[static_cast<std::size_t>(i + rx)] * in(std::clamp(x + i, 0, w - 1), y);
      tmp(x, y) = s;
    }
  Plane out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int i = -ry; i <= ry; ++i)
        s += ky[static_cast<std::size_t>(i + ry)] * tmp(x, std::clamp(y + i, 0, h - 1));
      out(x, y) = s;
    }
  return out;
}

// The three YCxCz planes of an image composited over mid grey (0.5 linear).
struct Opponent {
  Plane y, cx, cz;
};

// sRGB8 straight alpha -> linear RGB over 0.5 grey -> YCxCz (colour pipeline input).
Opponent toYCxCz(const ImageRGBA8& img) {
  const auto& lin = srgbTable();
  Opponent o{Plane(img.width, img.height), Plane(img.width, img.height),
             Plane(img.width, img.height)};
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint8_t* p = img.at(x, y);
      const double a = p[3] / 255.0;
      Color c;
      for (int k = 0; k < 3; ++k) c[k] = lin[p[k]] * a + 0.5 * (1.0 - a);
      const Color ycc = xyzToYCxCz(linearRgbToXyz(c));
      o.y(x, y) = ycc[0];
      o.cx(x, y) = ycc[1];
      o.cz(x, y) = ycc[2];
    }
  return o;
}

// The contrast sensitivity filters (colour pipeline, "spatial filtering"): per
// channel a 2D sum of Gaussians sampled on a (2r+1)^2 grid of pixels at
// 1/ppd degrees, r = ceil(3 sqrt(max b / (2 pi^2)) ppd), normalised to sum 1.
// Each Gaussian is separable; the blue-yellow filter is the weighted sum of
// two separable passes.
class CsfFilters {
 public:
  explicit CsfFilters(double ppd) {
    const double maxB = *std::max_element(std::begin(kB1), std::end(kB1));
    const double maxB2 = *std::max_element(std::begin(kB2), std::end(kB2));
    const int r = static_cast<int>(
        std::ceil(3.0 * std::sqrt(std::max(maxB, maxB2) / (2.0 * kPi * kPi)) * ppd));
    for (int ch = 0; ch < 3; ++ch) {
      auto& t = terms_[static_cast<std::size_t>(ch)];
      double total = 0.0;
      for (int term = 0; term < 2; ++term) {
        const double a = term == 0 ? kA1[ch] : kA2[ch];
        const double b = term == 0 ? kB1[ch] : kB2[ch];
        Term g;
        g.weight = a * std::sqrt(kPi / b);
        g.kernel.resize(static_cast<std::size_t>(2 * r + 1));
        double sum = 0.0;
        for (int i = -r; i <= r; ++i) {
          const double d = i / ppd;
          g.kernel[static_cast<std::size_t>(i + r)] = std::exp(-kPi * kPi * d * d / b);
          sum += g.kernel[static_cast<std::size_t>(i + r)];
        }
        total += g.weight * sum * sum;  // the 2D kernel's sum
        if (g.weight > 0.0) t.push_back(std::move(g));
      }
      for (auto& g : t) g.weight /= total;
    }
  }

  // Filters one YCxCz channel (0 = Y, 1 = Cx, 2 = Cz).
  Plane apply(const Plane& in, int channel) const {
    Plane out(in.width, in.height);
    for (const Term& g : terms_[static_cast<std::size_t>(channel)]) {
      const Plane part = convolveSeparable(in, g.kernel, g.kernel);
      for (std::size_t i = 0; i < out.v.size(); ++i) out.v[i] += g.weight * part.v[i];
    }
    return out;
  }

 private:
  struct Term {
    double weight = 0.0;
    std::vector<double> kernel;
  };
  std::array<std::vector<Term>, 3> terms_;
};

// The feature detectors (feature pipeline): a Gaussian of standard deviation
// sd = 0.5 gw ppd, r = ceil(3 sd), and its first and second derivatives along
// one axis; Gaussian weights sum to 1, the derivatives' positive weights to 1
// and negative ones to -1 (separably, as the 2D filters factor).
struct FeatureFilters {
  std::vector<double> g, dg, ddg;
  explicit FeatureFilters(double ppd) {
    const double sd = 0.5 * kGw * ppd;
    const int r = static_cast<int>(std::ceil(3.0 * sd));
    const std::size_t n = static_cast<std::size_t>(2 * r + 1);
    g.resize(n);
    dg.resize(n);
    ddg.resize(n);
    double gSum = 0.0, dPos = 0.0, dNeg = 0.0, ddPos = 0.0, ddNeg = 0.0;
    for (int i = -r; i <= r; ++i) {
      const std::size_t k = static_cast<std::size_t>(i + r);
      const double x = i;
      g[k] = std::exp(-x * x / (2.0 * sd * sd));
      dg[k] = -x * g[k];
      ddg[k] = (x * x / (sd * sd) - 1.0) * g[k];
      gSum += g[k];
      (dg[k] > 0.0 ? dPos : dNeg) += std::abs(dg[k]);
      (ddg[k] > 0.0 ? ddPos : ddNeg) += std::abs(ddg[k]);
    }
    for (std::size_t k = 0; k < n; ++k) {
      g[k] /= gSum;
      dg[k] /= dg[k] > 0.0 ? dPos : dNeg;
      ddg[k] /= ddg[k] > 0.0 ? ddPos : ddNeg;
    }
  }
};

// Edge and point strengths per pixel: the magnitude of the gradient and of the
// second-derivative pair of the normalised achromatic channel (Y + 16) / 116.
std::pair<Plane, Plane> detectFeatures(const Plane& yChannel, const FeatureFilters& f) {
  Plane yn(yChannel.width, yChannel.height);
  for (std::size_t i = 0; i < yn.v.size(); ++i) yn.v[i] = (yChannel.v[i] + 16.0) / 116.0;
  const Plane dx = convolveSeparable(yn, f.dg, f.g);
  const Plane dy = convolveSeparable(yn, f.g, f.dg);
  const Plane ddx = convolveSeparable(yn, f.ddg, f.g);
  const Plane ddy = convolveSeparable(yn, f.g, f.ddg);
  Plane edges(yn.width, yn.height), points(yn.width, yn.height);
  for (std::size_t i = 0; i < yn.v.size(); ++i) {
    edges.v[i] = std::hypot(dx.v[i], dy.v[i]);
    points.v[i] = std::hypot(ddx.v[i], ddy.v[i]);
  }
  return {std::move(edges), std::move(points)};
}

// Filtered YCxCz -> clamped linear RGB -> Hunt-adjusted L*a*b* per pixel.
std::vector<Color> perceptual(const Opponent& o, const CsfFilters& csf) {
  const Plane y = csf.apply(o.y, 0), cx = csf.apply(o.cx, 1), cz = csf.apply(o.cz, 2);
  std::vector<Color> out(y.v.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    Color rgb = xyzToLinearRgb(yCxCzToXyz({y.v[i], cx.v[i], cz.v[i]}));
    for (double& c : rgb) c = std::clamp(c, 0.0, 1.0);
    out[i] = huntAdjust(xyzToLab(linearRgbToXyz(rgb)));
  }
  return out;
}

// Checks that both images are non-empty, consistent and of the same size.
void checkPair(const ImageRGBA8& a, const ImageRGBA8& b) {
  auto consistent = [](const ImageRGBA8& img) {
    return img.width > 0 && img.height > 0 &&
           img.pixels.size() == static_cast<std::size_t>(img.width) * img.height * 4;
  };
  if (!consistent(a) || !consistent(b))
    throw std::invalid_argument("compareImages: empty or inconsistent image");
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument("compareImages: sizes differ (" + std::to_string(a.width) + "x" +
                                std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                                std::to_string(b.height) + ")");
}

// The diff heat map: t in [0, 1] -> black, red (1/3), yellow (2/3), white (1).
void heat(double t, std::uint8_t* out) {
  t = std::clamp(std::isnan(t) ? 1.0 : t, 0.0, 1.0);
  const double r = std::min(1.0, 3.0 * t);
  const double g = std::clamp(3.0 * t - 1.0, 0.0, 1.0);
  const double b = std::clamp(3.0 * t - 2.0, 0.0, 1.0);
  out[0] = static_cast<std::uint8_t>(std::lround(255.0 * r));
  out[1] = static_cast<std::uint8_t>(std::lround(255.0 * g));
  out[2] = static_cast<std::uint8_t>(std::lround(255.0 * b));
  out[3] = 255;
}

}  // namespace

// The LDR-FLIP error map (paper: colour pipeline, feature pipeline, final
// error E = colour^(1 - feature)), the reference implementation's constants.
std::vector<double> flipErrorMap(const ImageRGBA8& reference, const ImageRGBA8& test,
                                 double pixelsPerDegree) {
  checkPair(reference, test);
  if (!(pixelsPerDegree > 0.0) || !std::isfinite(pixelsPerDegree))
    throw std::invalid_argument("flipErrorMap: pixels per degree must be positive");
  const Opponent ref = toYCxCz(reference), tst = toYCxCz(test);

  // Colour pipeline: CSF filtering, Hunt-adjusted L*a*b*, HyAB^qc, then
  // redistribution of [0, pc cmax) to [0, pt) and [pc cmax, cmax] to [pt, 1].
  const CsfFilters csf(pixelsPerDegree);
  const std::vector<Color> labRef = perceptual(ref, csf), labTst = perceptual(tst, csf);
  const double cmax = flipCmax();
  const double pccmax = kPc * cmax;

  // Feature pipeline on the unfiltered achromatic channel.
  const FeatureFilters filters(pixelsPerDegree);
  const auto [edgesRef, pointsRef] = detectFeatures(ref.y, filters);
  const auto [edgesTst, pointsTst] = detectFeatures(tst.y, filters);

  std::vector<double> error(labRef.size());
  for (std::size_t i = 0; i < error.size(); ++i) {
    const double e = std::pow(hyab(labRef[i], labTst[i]), kQc);
    const double colour =
        e < pccmax ? e * kPt / pccmax : kPt + (e - pccmax) / (cmax - pccmax) * (1.0 - kPt);
    const double featureDiff = std::max(std::abs(edgesRef.v[i] - edgesTst.v[i]),
                                        std::abs(pointsRef.v[i] - pointsTst.v[i]));
    const double feature = std::pow(featureDiff / std::sqrt(2.0), kQf);
    error[i] = std::pow(colour, 1.0 - feature);
  }
  return error;
}

// MAE / PSNR / FLIP plus the RGB MAE, the alpha-mask IoU, the largest channel
// difference and the heat-map diff image (see the header).
ImageComparison compareImages(const ImageRGBA8& a, const ImageRGBA8& b, ImageMetric metric) {
  checkPair(a, b);
  const std::size_t n = static_cast<std::size_t>(a.width) * a.height;
  ImageComparison result;
  result.diff = ImageRGBA8(a.width, a.height);

  double sumAbs = 0.0, sumAbsRgb = 0.0, sumSq = 0.0, maxAbs = 0.0;
  std::size_t intersection = 0, unionCount = 0;
  std::vector<int> pixelMax(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = a.pixels.data() + 4 * i;
    const std::uint8_t* q = b.pixels.data() + 4 * i;
    int m = 0;
    for (int k = 0; k < 4; ++k) {
      const int d = std::abs(static_cast<int>(p[k]) - static_cast<int>(q[k]));
      sumAbs += d;
      sumSq += static_cast<double>(d) * d;
      if (k < 3) sumAbsRgb += d;
      m = std::max(m, d);
    }
    pixelMax[i] = m;
    maxAbs = std::max(maxAbs, static_cast<double>(m));
    const bool inA = p[3] >= 128, inB = q[3] >= 128;
    intersection += (inA && inB) ? 1 : 0;
    unionCount += (inA || inB) ? 1 : 0;
  }
  result.maeRgb = sumAbsRgb / (3.0 * static_cast<double>(n));
  result.maxAbs = maxAbs;
  result.alphaIoU =
      unionCount == 0 ? 1.0 : static_cast<double>(intersection) / static_cast<double>(unionCount);

  switch (metric) {
    case ImageMetric::Mae:
    case ImageMetric::Psnr: {
      const double mse = sumSq / (4.0 * static_cast<double>(n));
      result.value = metric == ImageMetric::Mae ? sumAbs / (4.0 * static_cast<double>(n))
                     : mse == 0.0               ? std::numeric_limits<double>::infinity()
                                                : 10.0 * std::log10(255.0 * 255.0 / mse);
      for (std::size_t i = 0; i < n; ++i)
        heat(std::sqrt(std::min(pixelMax[i], 32) / 32.0), result.diff.pixels.data() + 4 * i);
      break;
    }
    case ImageMetric::Flip: {
      const std::vector<double> map = flipErrorMap(a, b);
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        sum += map[i];
        heat(map[i], result.diff.pixels.data() + 4 * i);
      }
      result.value = sum / static_cast<double>(n);
      break;
    }
  }
  return result;
}

// Pass/fail against a tolerance: an upper bound for Mae and Flip, a lower
// bound (dB) for Psnr.
bool passes(const ImageComparison& comparison, ImageMetric metric, double tolerance) {
  switch (metric) {
    case ImageMetric::Mae:
    case ImageMetric::Flip:
      return comparison.value <= tolerance;
    case ImageMetric::Psnr:
      return comparison.value >= tolerance;
  }
  return false;
}

}  // namespace crumple::render
