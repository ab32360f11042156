// Image metrics (MAE, PSNR, FLIP), the diff heat map and contact sheets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "crumple/render/contact_sheet.hpp"
#include "crumple/render/image_compare.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render {
namespace {

// --- Test images (the same generators produced the FLIP reference values) ---

// A w x h image of one colour.
ImageRGBA8 uniform(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b,
                   std::uint8_t a = 255) {
  ImageRGBA8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = img.at(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
      p[3] = a;
    }
  return img;
}

// Sets the grey level of the pixels in [x0, x1) x [y0, y1).
void fillRect(ImageRGBA8& img, int x0, int y0, int x1, int y1, std::uint8_t v) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      std::uint8_t* p = img.at(x, y);
      p[0] = p[1] = p[2] = v;
    }
}

// 32x32 black with a white 8x8 square in the middle.
ImageRGBA8 square() {
  ImageRGBA8 img = uniform(32, 32, 0, 0, 0);
  fillRect(img, 12, 12, 20, 20, 255);
  return img;
}

// 32x32, black left of column `edge`, white from it on.
ImageRGBA8 step(int edge) {
  ImageRGBA8 img = uniform(32, 32, 0, 0, 0);
  fillRect(img, edge, 0, 32, 32, 255);
  return img;
}

// 32x32 one-pixel black/white checkerboard.
ImageRGBA8 checker() {
  ImageRGBA8 img = uniform(32, 32, 0, 0, 0);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) fillRect(img, x, y, x + 1, y + 1, ((x + y) & 1) ? 255 : 0);
  return img;
}

// 40x24 colour ramps.
ImageRGBA8 gradient() {
  ImageRGBA8 img(40, 24);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 40; ++x) {
      std::uint8_t* p = img.at(x, y);
      p[0] = static_cast<std::uint8_t>(x * 6);
      p[1] = static_cast<std::uint8_t>(y * 10);
      p[2] = static_cast<std::uint8_t>(200 - x * 3);
      p[3] = 255;
    }
  return img;
}

// Deterministic +-10 noise on the colour channels (an LCG).
ImageRGBA8 noisy(ImageRGBA8 img) {
  std::uint32_t s = 12345;
  for (std::size_t k = 0; k < img.pixels.size(); ++k) {
    if (k % 4 == 3) continue;
    s = s * 1664525u + 1013904223u;
    const int v = img.pixels[k] + static_cast<int>((s >> 24) % 21) - 10;
    img.pixels[k] = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
  }
  return img;
}

// The mean FLIP of a vs b.
double flip(const ImageRGBA8& a, const ImageRGBA8& b) {
  return compareImages(a, b, ImageMetric::Flip).value;
}

// One pixel's RGBA as a vector (for readable comparisons).
std::vector<std::uint8_t> rgbaAt(const ImageRGBA8& img, int x, int y) {
  const std::uint8_t* p = img.at(x, y);
  return {p[0], p[1], p[2], p[3]};
}

// --- MAE / PSNR ---------------------------------------------------------------

TEST(ImageCompare, MaeAndPsnrOfKnownDifference) {
  // Every pixel differs by (2, 0, 3, 0).
  const ImageRGBA8 a = uniform(4, 3, 10, 20, 30);
  const ImageRGBA8 b = uniform(4, 3, 12, 20, 27);
  const ImageComparison mae = compareImages(a, b, ImageMetric::Mae);
  EXPECT_DOUBLE_EQ(mae.value, 5.0 / 4.0);
  EXPECT_DOUBLE_EQ(mae.maeRgb, 5.0 / 3.0);
  EXPECT_DOUBLE_EQ(mae.maxAbs, 3.0);
  EXPECT_DOUBLE_EQ(mae.alphaIoU, 1.0);
  const ImageComparison psnr = compareImages(a, b, ImageMetric::Psnr);
  EXPECT_NEAR(psnr.value, 10.0 * std::log10(255.0 * 255.0 / (13.0 / 4.0)), 1e-12);
  EXPECT_DOUBLE_EQ(psnr.maeRgb, mae.maeRgb);
}

TEST(ImageCompare, MaeCountsAlphaAndOnlyChangedPixels) {
  const ImageRGBA8 a = uniform(10, 10, 50, 50, 50);
  ImageRGBA8 b = a;
  b.at(3, 4)[3] = 155;  // one pixel's alpha differs by 100
  const ImageComparison c = compareImages(a, b, ImageMetric::Mae);
  EXPECT_DOUBLE_EQ(c.value, 100.0 / 400.0);
  EXPECT_DOUBLE_EQ(c.maeRgb, 0.0);
  EXPECT_DOUBLE_EQ(c.maxAbs, 100.0);
}

TEST(ImageCompare, IdenticalImages) {
  const ImageRGBA8 img = noisy(gradient());
  for (ImageMetric m : {ImageMetric::Mae, ImageMetric::Psnr, ImageMetric::Flip}) {
    const ImageComparison c = compareImages(img, img, m);
    EXPECT_EQ(c.maeRgb, 0.0);
    EXPECT_EQ(c.maxAbs, 0.0);
    EXPECT_EQ(c.alphaIoU, 1.0);
    EXPECT_TRUE(passes(c, m, 0.0));
    ASSERT_EQ(c.diff.width, img.width);
    ASSERT_EQ(c.diff.height, img.height);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        ASSERT_EQ(rgbaAt(c.diff, x, y), (std::vector<std::uint8_t>{0, 0, 0, 255}));
  }
  EXPECT_EQ(compareImages(img, img, ImageMetric::Mae).value, 0.0);
  EXPECT_EQ(compareImages(img, img, ImageMetric::Psnr).value,
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(compareImages(img, img, ImageMetric::Flip).value, 0.0);
}

TEST(ImageCompare, AlphaIoU) {
  ImageRGBA8 a = uniform(8, 2, 0, 0, 0, 0);
  ImageRGBA8 b = a;
  EXPECT_DOUBLE_EQ(compareImages(a, b, ImageMetric::Mae).alphaIoU, 1.0);  // both empty
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) a.at(x, y)[3] = 128;  // covered (>= 128)
    for (int x = 0; x < 6; ++x) b.at(x, y)[3] = 255;
    a.at(7, y)[3] = 127;  // not covered
  }
  EXPECT_DOUBLE_EQ(compareImages(a, b, ImageMetric::Mae).alphaIoU, 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(compareImages(a, uniform(8, 2, 0, 0, 0, 0), ImageMetric::Psnr).alphaIoU, 0.0);
}

TEST(ImageCompare, DiffHeatMap) {
  const ImageRGBA8 a = uniform(4, 1, 100, 100, 100);
  ImageRGBA8 b = a;
  b.at(1, 0)[1] = 101;  // d = 1: visibly dark red
  b.at(2, 0)[2] = 108;  // d = 8: t = 0.5, orange
  b.at(3, 0)[0] = 140;  // d = 40 >= 32: white
  for (ImageMetric m : {ImageMetric::Mae, ImageMetric::Psnr}) {
    const ImageComparison c = compareImages(a, b, m);
    EXPECT_EQ(rgbaAt(c.diff, 0, 0), (std::vector<std::uint8_t>{0, 0, 0, 255}));
    EXPECT_EQ(rgbaAt(c.diff, 1, 0), (std::vector<std::uint8_t>{135, 0, 0, 255}));
    EXPECT_EQ(rgbaAt(c.diff, 2, 0), (std::vector<std::uint8_t>{255, 128, 0, 255}));
    EXPECT_EQ(rgbaAt(c.diff, 3, 0), (std::vector<std::uint8_t>{255, 255, 255, 255}));
  }
}

TEST(ImageCompare, RejectsMismatchedOrEmptyImages) {
  EXPECT_THROW(compareImages(uniform(4, 4, 0, 0, 0), uniform(4, 5, 0, 0, 0), ImageMetric::Mae),
               std::invalid_argument);
  EXPECT_THROW(compareImages(uniform(4, 4, 0, 0, 0), uniform(5, 4, 0, 0, 0), ImageMetric::Flip),
               std::invalid_argument);
  EXPECT_THROW(compareImages(ImageRGBA8(), ImageRGBA8(), ImageMetric::Psnr), std::invalid_argument);
  ImageRGBA8 broken = uniform(4, 4, 0, 0, 0);
  broken.pixels.pop_back();
  EXPECT_THROW(compareImages(broken, uniform(4, 4, 0, 0, 0), ImageMetric::Mae),
               std::invalid_argument);
  EXPECT_THROW(flipErrorMap(uniform(4, 4, 0, 0, 0), uniform(4, 4, 0, 0, 0), 0.0),
               std::invalid_argument);
}

TEST(ImageCompare, PassesUsesTheMetricsDirection) {
  ImageComparison c;
  c.value = 1.25;
  EXPECT_TRUE(passes(c, ImageMetric::Mae, 1.25));
  EXPECT_FALSE(passes(c, ImageMetric::Mae, 1.2));
  EXPECT_TRUE(passes(c, ImageMetric::Flip, 2.0));
  EXPECT_FALSE(passes(c, ImageMetric::Flip, 1.0));
  c.value = 42.0;
  EXPECT_TRUE(passes(c, ImageMetric::Psnr, 40.0));
  EXPECT_TRUE(passes(c, ImageMetric::Psnr, 42.0));
  EXPECT_FALSE(passes(c, ImageMetric::Psnr, 45.0));
  c.value = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(passes(c, ImageMetric::Psnr, 1e9));
  c.value = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(passes(c, ImageMetric::Mae, 1e9));
  EXPECT_FALSE(passes(c, ImageMetric::Psnr, -1e9));
  EXPECT_FALSE(passes(c, ImageMetric::Flip, 1e9));
}

// --- FLIP ---------------------------------------------------------------------

// By hand for uniform images (the normalised CSF filters leave them unchanged,
// the feature detectors see nothing, so the error is the redistributed colour
// error): black vs white have Hunt-adjusted L*a*b* (0, 0, 0) and (100, 0, 0),
// HyAB 100, 100^0.7 = 25.1189; cmax = HyAB(green (87.74, -75.61, 72.98), blue
// (32.30, 25.58, -34.84))^0.7 = 203.30^0.7 = 41.2761, pc cmax = 16.5104, so
// E = 0.95 + (25.1189 - 16.5104) / (41.2761 - 16.5104) * 0.05 = 0.967380.
// NVIDIA's reference implementation (FLIP.h, float) gives 0.967391.
TEST(ImageCompareFlip, BlackVersusWhite) {
  const double e = flip(uniform(16, 16, 0, 0, 0), uniform(16, 16, 255, 255, 255));
  EXPECT_NEAR(e, 0.967380, 2e-6);
  EXPECT_NEAR(e, 0.967391, 5e-5);
  // Every pixel the same: heat(0.96738) = (255, 255, 230).
  const ImageComparison c =
      compareImages(uniform(16, 16, 0, 0, 0), uniform(16, 16, 255, 255, 255), ImageMetric::Flip);
  EXPECT_EQ(rgbaAt(c.diff, 5, 7), (std::vector<std::uint8_t>{255, 255, 230, 255}));
  EXPECT_DOUBLE_EQ(c.maeRgb, 255.0);
}

// By hand as above: sRGB (128, 128, 128) -> L*a*b* (53.585, 0, 0); (160, 100,
// 60) -> L* 48.153, Hunt-adjusted (9.7405, 15.6368); HyAB = 5.4321 + 18.4225 =
// 23.8546, ^0.7 = 9.2108 < pc cmax, E = 0.95 / 16.5104 * 9.2108 = 0.529986
// (reference 0.530020). One sRGB level of grey: E = 0.029855 (reference 0.029868).
TEST(ImageCompareFlip, UniformColoursByHand) {
  EXPECT_NEAR(flip(uniform(16, 16, 128, 128, 128), uniform(16, 16, 160, 100, 60)), 0.529986, 5e-6);
  EXPECT_NEAR(flip(uniform(16, 16, 128, 128, 128), uniform(16, 16, 129, 129, 129)), 0.029855, 5e-6);
}

// Non-uniform cases exercising the CSF filters and the edge and point
// detectors, against the mean FLIP of NVIDIA's reference implementation
// (FLIP.h, LDR, default 67.02 pixels per degree) on the same images.
TEST(ImageCompareFlip, MatchesTheReferenceImplementation) {
  EXPECT_NEAR(flip(square(), uniform(32, 32, 0, 0, 0)), 0.1537889, 1e-4);
  EXPECT_NEAR(flip(step(16), step(17)), 0.1034634, 1e-4);
  EXPECT_NEAR(flip(checker(), uniform(32, 32, 188, 188, 188)), 0.0260619, 1e-4);
  EXPECT_NEAR(flip(gradient(), noisy(gradient())), 0.0619211, 1e-4);
}

// RGB is composited over 0.5 linear grey (sRGB 188 = 0.5029) by alpha.
TEST(ImageCompareFlip, CompositesOverMidGrey) {
  // Transparent vs opaque 188 grey: nearly the same colour (reference 0.0171199).
  EXPECT_NEAR(flip(uniform(16, 16, 0, 0, 0, 0), uniform(16, 16, 188, 188, 188)), 0.0171199, 5e-5);
  // The colour of a transparent pixel does not matter.
  EXPECT_EQ(flip(uniform(16, 16, 0, 0, 0, 0), uniform(16, 16, 255, 40, 7, 0)), 0.0);
  // Half-transparent red vs opaque red (reference 0.8418319).
  EXPECT_NEAR(flip(uniform(16, 16, 255, 0, 0, 128), uniform(16, 16, 255, 0, 0, 255)), 0.8418319,
              1e-4);
}

TEST(ImageCompareFlip, MapIsSymmetricBoundedAndLocal) {
  const ImageRGBA8 a = square();
  ImageRGBA8 b = uniform(32, 32, 0, 0, 0);
  const std::vector<double> ab = flipErrorMap(a, b), ba = flipErrorMap(b, a);
  ASSERT_EQ(ab.size(), 32u * 32u);
  for (std::size_t i = 0; i < ab.size(); ++i) {
    EXPECT_NEAR(ab[i], ba[i], 1e-12);
    EXPECT_GE(ab[i], 0.0);
    EXPECT_LE(ab[i], 1.0);
  }
  // Largest inside the square, small far from it (the filters are local).
  EXPECT_GT(ab[16 * 32 + 16], 0.5);
  EXPECT_LT(ab[0], 0.05);
  // A larger viewing distance (more pixels per degree) blurs the checkerboard
  // more: it reads even closer to flat grey.
  const ImageRGBA8 grey = uniform(32, 32, 188, 188, 188);
  double near = 0.0, far = 0.0;
  for (double v : flipErrorMap(checker(), grey, 30.0)) near += v;
  for (double v : flipErrorMap(checker(), grey, kFlipPixelsPerDegree)) far += v;
  EXPECT_LT(far, near);
  EXPECT_NEAR(kFlipPixelsPerDegree, 67.0206, 1e-4);
}

// --- Contact sheets -------------------------------------------------------------

// How many label-ink pixels lie in [x0, x1) x [y0, y1).
int inkCount(const ImageRGBA8& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += img.at(x, y)[0] == kContactSheetInk ? 1 : 0;
  return n;
}

TEST(ContactSheet, LayoutOrderAndOpacity) {
  std::vector<std::pair<int, ImageRGBA8>> frames;
  for (int i = 0; i < 5; ++i)
    frames.emplace_back(i * 10, uniform(40, 20, static_cast<std::uint8_t>(40 * i + 10), 60,
                                        static_cast<std::uint8_t>(200 - 30 * i)));
  const ImageRGBA8 sheet = makeContactSheet(frames, 0, 20);  // 3 columns, 2 rows
  const int g = kContactSheetGap, cw = 20, ch = 10, label = 7 + 4;
  ASSERT_EQ(sheet.width, 3 * cw + 4 * g);
  ASSERT_EQ(sheet.height, 2 * (ch + label) + 3 * g);
  for (int i = 0; i < 5; ++i) {
    const int x0 = g + (i % 3) * (cw + g), y0 = g + (i / 3) * (ch + label + g);
    for (int y = y0; y < y0 + ch; ++y)
      for (int x = x0; x < x0 + cw; ++x)
        ASSERT_EQ(rgbaAt(sheet, x, y),
                  (std::vector<std::uint8_t>{static_cast<std::uint8_t>(40 * i + 10), 60,
                                             static_cast<std::uint8_t>(200 - 30 * i), 255}))
            << "frame " << i << " at " << x << "," << y;
  }
  // The sixth slot and the gaps are background.
  const int x5 = g + 2 * (cw + g), y5 = g + ch + label + g;
  EXPECT_EQ(rgbaAt(sheet, x5 + 10, y5 + 5), (std::vector<std::uint8_t>{32, 32, 32, 255}));
  EXPECT_EQ(rgbaAt(sheet, 1, 1), (std::vector<std::uint8_t>{32, 32, 32, 255}));
  for (std::size_t k = 3; k < sheet.pixels.size(); k += 4) ASSERT_EQ(sheet.pixels[k], 255);

  // Explicit columns; more columns than frames shrink to the frame count.
  EXPECT_EQ(makeContactSheet(frames, 1, 20).width, cw + 2 * g);
  EXPECT_EQ(makeContactSheet(frames, 1, 20).height, 5 * (ch + label) + 6 * g);
  EXPECT_EQ(makeContactSheet(frames, 9, 20).width, 5 * cw + 6 * g);
}

TEST(ContactSheet, BoxFilterInLinearLightWithPremultipliedAlpha) {
  // A one-pixel checkerboard halved: each cell pixel averages two black and
  // two white pixels in linear light (0.5 -> sRGB 188, not 128).
  ImageRGBA8 check = uniform(8, 8, 0, 0, 0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      if ((x + y) & 1) fillRect(check, x, y, x + 1, y + 1, 255);
  ImageRGBA8 sheet = makeContactSheet({{0, check}}, 1, 4);
  const int g = kContactSheetGap;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      EXPECT_EQ(rgbaAt(sheet, g + x, g + y), (std::vector<std::uint8_t>{188, 188, 188, 255}));

  // Transparent black next to opaque white: premultiplied average = white at
  // alpha 0.5, over grey 0.5 * 1 + 0.5 * 0.5 = 0.75 linear = sRGB 225 (a
  // straight-alpha average would give grey 0.5, sRGB 188).
  ImageRGBA8 pair = uniform(2, 1, 0, 0, 0, 0);
  pair.at(1, 0)[0] = pair.at(1, 0)[1] = pair.at(1, 0)[2] = pair.at(1, 0)[3] = 255;
  sheet = makeContactSheet({{0, pair}}, 1, 1);
  EXPECT_EQ(rgbaAt(sheet, g, g), (std::vector<std::uint8_t>{225, 225, 225, 255}));

  // A fully transparent frame reads as mid grey.
  sheet = makeContactSheet({{0, uniform(6, 6, 255, 0, 0, 0)}}, 1, 3);
  EXPECT_EQ(rgbaAt(sheet, g + 1, g + 1), (std::vector<std::uint8_t>{188, 188, 188, 255}));

  // Non-integer ratios: a 3-pixel-wide ramp into 2 pixels weights the middle
  // source pixel half to each side; upscaling repeats pixels.
  ImageRGBA8 ramp = uniform(3, 3, 0, 0, 0);
  fillRect(ramp, 2, 0, 3, 3, 255);
  sheet = makeContactSheet({{0, ramp}}, 1, 2);
  EXPECT_EQ(sheet.at(g, g)[0], 0);
  EXPECT_EQ(sheet.at(g + 1, g)[0], linearToSrgb8(2.0 / 3.0));  // 213
  sheet = makeContactSheet({{0, ramp}}, 1, 6);
  EXPECT_EQ(sheet.at(g + 3, g)[0], 0);
  EXPECT_EQ(sheet.at(g + 4, g)[0], 255);
}

TEST(ContactSheet, FrameNumbersAreDrawn) {
  // Ink pixels per glyph of the 5x7 font (a digit's bit count).
  const int bits[10] = {19, 10, 14, 14, 14, 17, 15, 11, 17, 15};
  const int g = kContactSheetGap;
  std::set<std::string> bitmaps;  // each label's pixels
  for (int d = 0; d < 10; ++d) {
    const ImageRGBA8 sheet = makeContactSheet({{d, uniform(40, 20, 0, 0, 0)}}, 1, 40);
    // The label strip under the 40x20 cell.
    EXPECT_EQ(inkCount(sheet, 0, g + 20, sheet.width, sheet.height), bits[d]) << d;
    EXPECT_EQ(inkCount(sheet, 0, 0, sheet.width, g + 20), 0);
    std::string bitmap;
    for (int y = g + 20; y < sheet.height; ++y)
      for (int x = 0; x < sheet.width; ++x) bitmap.push_back(static_cast<char>(sheet.at(x, y)[0]));
    bitmaps.insert(bitmap);
  }
  EXPECT_EQ(bitmaps.size(), 10u);  // every digit looks different

  // Multi-digit and negative numbers, centred under the cell.
  ImageRGBA8 sheet = makeContactSheet({{-18, uniform(40, 20, 0, 0, 0)}}, 1, 40);
  EXPECT_EQ(inkCount(sheet, 0, g + 20, sheet.width, sheet.height), 5 + bits[1] + bits[8]);
  int minX = sheet.width, maxX = -1;
  for (int y = g + 20; y < sheet.height; ++y)
    for (int x = 0; x < sheet.width; ++x)
      if (sheet.at(x, y)[0] == kContactSheetInk) {
        minX = std::min(minX, x);
        maxX = std::max(maxX, x);
      }
  EXPECT_EQ(maxX - minX + 1, 3 * 6 - 1);                     // "-18" is 17 px wide
  EXPECT_LE(std::abs((minX + maxX + 1) - (2 * g + 40)), 1);  // centred

  // Large cells scale the digits 2x.
  sheet = makeContactSheet({{8, uniform(64, 32, 0, 0, 0)}}, 1, kContactSheetLargeCell);
  EXPECT_EQ(sheet.height, 160 + 14 + 4 + 2 * g);
  EXPECT_EQ(inkCount(sheet, 0, g + 160, sheet.width, sheet.height), 4 * bits[8]);
}

TEST(ContactSheet, RejectsBadInput) {
  EXPECT_THROW(makeContactSheet({}, 0, 100), std::invalid_argument);
  EXPECT_THROW(makeContactSheet({{0, uniform(4, 4, 0, 0, 0)}, {1, uniform(4, 5, 0, 0, 0)}}, 0, 10),
               std::invalid_argument);
  EXPECT_THROW(makeContactSheet({{0, ImageRGBA8()}}, 0, 10), std::invalid_argument);
  EXPECT_THROW(makeContactSheet({{0, uniform(4, 4, 0, 0, 0)}}, 0, 0), std::invalid_argument);
  EXPECT_THROW(makeContactSheet({{0, uniform(4, 4, 0, 0, 0)}}, -1, 10), std::invalid_argument);
  EXPECT_THROW(makeContactSheet({{0, uniform(4, 4, 0, 0, 0)}}, 0, 70000), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::render
