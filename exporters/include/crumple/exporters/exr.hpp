#pragma once
// OpenEXR images (linear light, premultiplied alpha: the EXR convention and
// ImageRGBAF's) through the OpenEXR library.
//
// Written files: scanline, one part, channels R, G, B, A as HALF, ZIP
// compression (16 scanlines per block), data window = display window = the
// image, no other header attributes than OpenEXR's required ones (channels,
// compression, dataWindow, displayWindow, lineOrder, pixelAspectRatio,
// screenWindowCenter, screenWindowWidth): in particular no time stamp, so
// identical images give identical files (for a given OpenEXR and zlib).
#include <string>

#include "crumple/core/image.hpp"

namespace crumple::exporters {

// Largest finite half-float value: pixel values beyond +-kExrHalfMax
// (infinities included) are written as +-kExrHalfMax; NaN stays NaN (a
// renderer bug stays visible). Every other value is rounded to the nearest
// half (relative error <= 2^-11, absolute <= 2^-25 below 2^-14).
inline constexpr float kExrHalfMax = 65504.0f;

// Writes atomically: the file is encoded in memory, written to PATH.tmp and
// renamed over PATH; on failure the temporary file is removed. Throws
// InputError naming the file if it cannot be written (missing or read-only
// folder, full disk), std::invalid_argument for an empty or inconsistent
// image (pixels.size() != width * height * 4).
void writeExr(const std::string& path, const ImageRGBAF& image);

// Reads any single-part flat (scanline or tiled) OpenEXR file with R, G and B
// channels (any pixel type, converted to float) and optionally A (1 when
// absent). The image is the file's data window, rows top to bottom. Throws
// InputError naming the file when it is missing, not an OpenEXR file,
// malformed or truncated, lacks R, G or B, or is larger than 2^28 pixels.
ImageRGBAF readExr(const std::string& path);

}  // namespace crumple::exporters
