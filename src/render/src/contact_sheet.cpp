// Contact sheets: box-filtered thumbnails in a grid, labelled with a built-in
// 5x7 bitmap digit font.
#include "crumple/render/contact_sheet.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "crumple/render/view.hpp"

namespace crumple::render {
namespace {

// 5x7 glyphs for '0'..'9' and '-': one row per byte, top row first, bit 4 =
// leftmost column.
constexpr std::array<std::array<std::uint8_t, 7>, 11> kGlyphs = {{
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E},  // 0
    {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},  // 1
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F},  // 2
    {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},  // 3
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02},  // 4
    {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},  // 5
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E},  // 6
    {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},  // 7
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E},  // 8
    {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},  // 9
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00},  // -
}};
constexpr int kGlyphW = 5;
constexpr int kGlyphH = 7;
constexpr int kMaxSide = 65535;

// One output sample's source pixels and their normalised weights along an axis.
struct Taps {
  std::vector<std::pair<int, double>> taps;
};

// Box-filter weights along one axis resampling `src` pixels to `dst`: output
// pixel i covers [i, i+1) * src / dst of the source, each source pixel weighted
// by its overlap (weights sum to 1).
std::vector<Taps> boxWeights(int src, int dst) {
  std::vector<Taps> out(static_cast<std::size_t>(dst));
  const double scale = static_cast<double>(src) / dst;
  for (int i = 0; i < dst; ++i) {
    const double lo = i * scale, hi = (i + 1) * scale;
    const int first = std::clamp(static_cast<int>(std::floor(lo)), 0, src - 1);
    const int last = std::clamp(static_cast<int>(std::ceil(hi)) - 1, first, src - 1);
    double total = 0.0;
    for (int s = first; s <= last; ++s) {
      const double w = std::min(hi, s + 1.0) - std::max(lo, static_cast<double>(s));
      if (w > 0.0) {
        out[static_cast<std::size_t>(i)].taps.emplace_back(s, w);
        total += w;
      }
    }
    for (auto& [s, w] : out[static_cast<std::size_t>(i)].taps) w /= total;
  }
  return out;
}

// Resizes a frame to w x h by the linear-light, premultiplied box filter and
// composites it over 0.5 linear grey into `sheet` at (x0, y0).
void drawThumbnail(const ImageRGBA8& frame, int w, int h, ImageRGBA8& sheet, int x0, int y0) {
  static const std::array<double, 256> lin = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i)
      t[static_cast<std::size_t>(i)] = srgb8ToLinear(static_cast<std::uint8_t>(i));
    return t;
  }();
  const std::vector<Taps> wx = boxWeights(frame.width, w), wy = boxWeights(frame.height, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Premultiplied average: sum of w * (alpha * colour) and of w * alpha.
      double acc[4] = {0.0, 0.0, 0.0, 0.0};
      for (const auto& [sy, vy] : wy[static_cast<std::size_t>(y)].taps)
        for (const auto& [sx, vx] : wx[static_cast<std::size_t>(x)].taps) {
          const std::uint8_t* p = frame.at(sx, sy);
          const double a = p[3] / 255.0, wt = vx * vy;
          for (int k = 0; k < 3; ++k) acc[k] += wt * a * lin[p[k]];
          acc[3] += wt * a;
        }
      // Unpremultiplying (colour = acc / alpha) and compositing over grey
      // (colour * alpha + 0.5 (1 - alpha)) reduce to acc + 0.5 (1 - alpha).
      std::uint8_t* q = sheet.at(x0 + x, y0 + y);
      for (int k = 0; k < 3; ++k) q[k] = linearToSrgb8(acc[k] + 0.5 * (1.0 - acc[3]));
      q[3] = 255;
    }
}

// Draws `text` (digits and '-') with its top-left corner at (x0, y0), each
// glyph pixel a scale x scale square, clipped to [clipX0, clipX1) horizontally.
void drawText(ImageRGBA8& sheet, const std::string& text, int x0, int y0, int scale, int clipX0,
              int clipX1) {
  for (std::size_t c = 0; c < text.size(); ++c) {
    const std::size_t glyph = text[c] == '-' ? 10 : static_cast<std::size_t>(text[c] - '0');
    const int gx = x0 + static_cast<int>(c) * (kGlyphW + 1) * scale;
    for (int row = 0; row < kGlyphH; ++row)
      for (int col = 0; col < kGlyphW; ++col) {
        if (!(kGlyphs[glyph][static_cast<std::size_t>(row)] & (0x10 >> col))) continue;
        for (int dy = 0; dy < scale; ++dy)
          for (int dx = 0; dx < scale; ++dx) {
            const int px = gx + col * scale + dx, py = y0 + row * scale + dy;
            if (px < clipX0 || px >= clipX1 || px < 0 || px >= sheet.width || py < 0 ||
                py >= sheet.height)
              continue;
            std::uint8_t* q = sheet.at(px, py);
            q[0] = q[1] = q[2] = kContactSheetInk;
            q[3] = 255;
          }
      }
  }
}

}  // namespace

// The contact sheet grid (layout documented in the header).
ImageRGBA8 makeContactSheet(const std::vector<std::pair<int, ImageRGBA8>>& frames, int columns,
                            int cellWidth) {
  if (frames.empty()) throw std::invalid_argument("makeContactSheet: no frames");
  if (columns < 0) throw std::invalid_argument("makeContactSheet: columns must be >= 0");
  if (cellWidth <= 0) throw std::invalid_argument("makeContactSheet: cellWidth must be > 0");
  const int fw = frames.front().second.width, fh = frames.front().second.height;
  for (const auto& [number, img] : frames) {
    if (img.width <= 0 || img.height <= 0 ||
        img.pixels.size() != static_cast<std::size_t>(img.width) * img.height * 4)
      throw std::invalid_argument("makeContactSheet: frame " + std::to_string(number) +
                                  " is empty or inconsistent");
    if (img.width != fw || img.height != fh)
      throw std::invalid_argument("makeContactSheet: frame " + std::to_string(number) + " is " +
                                  std::to_string(img.width) + "x" + std::to_string(img.height) +
                                  ", expected " + std::to_string(fw) + "x" + std::to_string(fh));
  }

  const long long n = static_cast<long long>(frames.size());
  long long cols =
      columns == 0 ? static_cast<long long>(std::ceil(std::sqrt(static_cast<double>(n)))) : columns;
  cols = std::clamp(cols, 1LL, n);
  const long long rows = (n + cols - 1) / cols;
  const long long cellHeight =
      std::max(1LL, std::llround(static_cast<double>(cellWidth) * fh / static_cast<double>(fw)));
  const int scale = cellWidth >= kContactSheetLargeCell ? 2 : 1;
  const int labelHeight = kGlyphH * scale + 4;
  const int g = kContactSheetGap;
  const long long width = cols * cellWidth + (cols + 1) * g;
  const long long height = rows * (cellHeight + labelHeight) + (rows + 1) * g;
  if (width > kMaxSide || height > kMaxSide)
    throw std::invalid_argument("makeContactSheet: the sheet would be " + std::to_string(width) +
                                "x" + std::to_string(height) + " pixels (at most " +
                                std::to_string(kMaxSide) + " a side)");

  ImageRGBA8 sheet(static_cast<int>(width), static_cast<int>(height));
  for (std::size_t i = 0; i < sheet.pixels.size(); i += 4) {
    sheet.pixels[i] = sheet.pixels[i + 1] = sheet.pixels[i + 2] = kContactSheetBackground;
    sheet.pixels[i + 3] = 255;
  }
  const int ch = static_cast<int>(cellHeight);
  for (long long i = 0; i < n; ++i) {
    const int col = static_cast<int>(i % cols), row = static_cast<int>(i / cols);
    const int x0 = g + col * (cellWidth + g);
    const int y0 = g + row * (ch + labelHeight + g);
    const auto& [number, img] = frames[static_cast<std::size_t>(i)];
    drawThumbnail(img, cellWidth, ch, sheet, x0, y0);
    const std::string text = std::to_string(number);
    const int textWidth = static_cast<int>(text.size()) * (kGlyphW + 1) * scale - scale;
    drawText(sheet, text, x0 + (cellWidth - textWidth) / 2, y0 + ch + 2, scale, x0, x0 + cellWidth);
  }
  return sheet;
}

}  // namespace crumple::render
