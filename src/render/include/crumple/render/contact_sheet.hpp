#pragma once
// A contact sheet: many frames of an animation side by side in one image, each
// labelled with its frame number, for reviewing a run at a glance.
#include <cstdint>
#include <utility>
#include <vector>

#include "crumple/core/image.hpp"

namespace crumple::render {

// Layout constants (pixels).
inline constexpr int kContactSheetGap = 4;  // around and between cells
// The label digits are 5x7 pixel glyphs, one pixel apart, drawn at this scale
// factor: 2 when cellWidth >= kContactSheetLargeCell, else 1.
inline constexpr int kContactSheetLargeCell = 320;
// The sheet's background and the label colour (sRGB).
inline constexpr std::uint8_t kContactSheetBackground = 32;
inline constexpr std::uint8_t kContactSheetInk = 235;

// Lays the frames out in a grid (in the given order: left to right, then top
// to bottom), each labelled with its number (first of the pair; a leading '-'
// for negative numbers).
// - columns: the grid's column count; 0 = automatic, ceil(sqrt(n)); more
//   columns than frames are reduced to the frame count.
// - Each frame is resized to cellWidth x cellHeight, cellHeight = max(1,
//   round(cellWidth * height / width)), by a box filter: every output pixel is
//   the area-weighted average of the source pixels it covers, in linear light
//   with premultiplied alpha, then composited over mid grey (0.5 linear, sRGB
//   188) so that transparent areas read.
// - Geometry, with g = kContactSheetGap, s = the digit scale and label height
//   L = 7 s + 4: sheet width = columns * cellWidth + (columns + 1) g, height =
//   rows * (cellHeight + L) + (rows + 1) g; cell (col, row) has its top-left
//   corner at (g + col (cellWidth + g), g + row (cellHeight + L + g)); its
//   label is centred horizontally under it, 2 px below, clipped to the cell's
//   width. Background kContactSheetBackground grey, digits kContactSheetInk.
// The result is fully opaque (alpha 255).
// Throws std::invalid_argument on no frames, frames of different sizes, an
// empty or inconsistent frame, columns < 0, cellWidth <= 0, or a sheet larger
// than 65535 pixels a side.
ImageRGBA8 makeContactSheet(const std::vector<std::pair<int, ImageRGBA8>>& frames, int columns,
                            int cellWidth);

}  // namespace crumple::render
