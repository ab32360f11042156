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

// The same file with more channels beside R, G, B, A (a multi-layer EXR in
// one part: "layer.channel" names, e.g. the renderers' AOVs), each as half or,
// when fullFloat, as 32-bit float (not clamped). Throws
// std::invalid_argument when `extra` is not the image's size, a channel has
// the wrong number of pixels, an empty name, one of R, G, B, A or a name
// given twice; otherwise as writeExr. An empty `extra` writes writeExr's
// bytes.
void writeExr(const std::string& path, const ImageRGBAF& image, const ImageChannels& extra);

// Reads any single-part flat (scanline or tiled) OpenEXR file with R, G and B
// channels (any pixel type, converted to float) and optionally A (1 when
// absent). The image is the file's data window, rows top to bottom. Throws
// InputError naming the file when it is missing, not an OpenEXR file,
// malformed or truncated, lacks R, G or B, or is larger than 2^28 pixels.
ImageRGBAF readExr(const std::string& path);

// Every channel of a single-part flat OpenEXR file (any pixel type, as
// float), in the file's (alphabetical) order, over its data window. Throws
// as readExr does, except that no channel is required.
ImageChannels readExrChannels(const std::string& path);

}  // namespace crumple::exporters
