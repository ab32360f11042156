// PNG through libpng. libpng reports errors by longjmp: every setjmp lives in
// a small function whose frame holds only trivially destructible objects, so
// no C++ destructor is ever skipped; the C++ callers own the resources and
// turn a failure into InputError.
#include "crumple/exporters/png.hpp"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include "crumple/core/error.hpp"
#include "image_write.hpp"

namespace crumple::exporters {
namespace {

// Fixed encoder settings: with no timestamp chunk, identical images give
// identical files (for a given libpng and zlib).
constexpr int kCompressionLevel = 6;
constexpr int kRowFilter = PNG_FILTER_PAETH;
// Reading limits: at most 65535 pixels a side and 2^28 pixels (1 GiB of RGBA).
constexpr png_uint_32 kMaxSide = 65535;
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 28;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// Where the error callback leaves libpng's message before it longjmps.
struct ErrorState {
  char message[256] = {};
};

[[noreturn]] void onError(png_structp png, png_const_charp message) {
  auto* state = static_cast<ErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", message ? message : "libpng error");
  png_longjmp(png, 1);
}

void onWarning(png_structp, png_const_charp) {}

std::string describe(const ErrorState& state) {
  return state.message[0] ? state.message : "libpng failed";
}

// libpng's write or read structs, made with the error callbacks above and
// destroyed with the matching call.
template <bool kWrite>
struct PngStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngStructs(const PngStructs&) = delete;
  PngStructs& operator=(const PngStructs&) = delete;
  explicit PngStructs(ErrorState* state) {
    png = kWrite ? png_create_write_struct(PNG_LIBPNG_VER_STRING, state, onError, onWarning)
                 : png_create_read_struct(PNG_LIBPNG_VER_STRING, state, onError, onWarning);
    if (png) info = png_create_info_struct(png);
  }
  ~PngStructs() {
    if constexpr (kWrite)
      png_destroy_write_struct(&png, &info);
    else
      png_destroy_read_struct(&png, &info, nullptr);
  }
};
using WriteStructs = PngStructs<true>;
using ReadStructs = PngStructs<false>;

// --- Writing ---------------------------------------------------------------

bool encode(png_structp png, png_infop info, std::FILE* file, png_bytepp rows, png_uint_32 width,
            png_uint_32 height) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, file);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // sRGB, plus the matching gAMA and cHRM for decoders that ignore sRGB.
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_set_compression_level(png, kCompressionLevel);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, kRowFilter);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

// --- Reading ---------------------------------------------------------------

// Sets up the conversion of any PNG to 8-bit RGBA and reads the header.
bool decodeHeader(png_structp png, png_infop info, std::FILE* file, png_uint_32* width,
                  png_uint_32* height, png_size_t* rowBytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, file);
  png_set_sig_bytes(png, 8);
  png_set_user_limits(png, kMaxSide, kMaxSide);
  png_read_info(png, info);
  const int colorType = png_get_color_type(png, info);
  const int bitDepth = png_get_bit_depth(png, info);
  const bool hasTrns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  if (colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colorType == PNG_COLOR_TYPE_GRAY && bitDepth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (hasTrns) png_set_tRNS_to_alpha(png);
  if (bitDepth == 16) png_set_scale_16(png);
  if (!(colorType & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(png);
  if (!(colorType & PNG_COLOR_MASK_ALPHA) && !hasTrns)
    png_set_add_alpha(png, 0xFF, PNG_FILLER_AFTER);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  *width = png_get_image_width(png, info);
  *height = png_get_image_height(png, info);
  *rowBytes = png_get_rowbytes(png, info);
  return true;
}

bool decodeRows(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

void writePng(const std::string& path, const ImageRGBA8& image) {
  checkImageToWrite(path, "PNG", image, "bytes");
  const std::string tmp = path + ".tmp";
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y) rows[y] = const_cast<png_bytep>(image.at(0, y));

  FilePtr file(std::fopen(tmp.c_str(), "wb"));
  if (!file) throw InputError(path, std::string("cannot write PNG: ") + std::strerror(errno));
  ErrorState state;
  std::string problem;
  {
    WriteStructs s(&state);
    if (!s.png || !s.info) {
      problem = "out of memory";
    } else if (!encode(s.png, s.info, file.get(), rows.data(),
                       static_cast<png_uint_32>(image.width),
                       static_cast<png_uint_32>(image.height))) {
      problem = describe(state);
    }
  }
  finishAtomicWrite(file.release(), tmp, path, "PNG", problem);
}

namespace {

// Decodes a PNG from an open stream; `path` names it in errors.
ImageRGBA8 decodePng(const FilePtr& file, const std::string& path) {
  png_byte signature[8] = {};
  if (std::fread(signature, 1, sizeof signature, file.get()) != sizeof signature ||
      png_sig_cmp(signature, 0, sizeof signature) != 0)
    throw InputError(path, "not a PNG file");

  ErrorState state;
  ReadStructs s(&state);
  if (!s.png || !s.info) throw InputError(path, "cannot read PNG: out of memory");
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  png_size_t rowBytes = 0;
  if (!decodeHeader(s.png, s.info, file.get(), &width, &height, &rowBytes))
    throw InputError(path, "malformed PNG: " + describe(state));
  if (static_cast<std::uint64_t>(width) * height > kMaxPixels)
    throw InputError(
        path, "PNG too large (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (png_get_bit_depth(s.png, s.info) != 8 || png_get_channels(s.png, s.info) != 4 ||
      rowBytes != static_cast<png_size_t>(width) * 4)
    throw InputError(path, "unsupported PNG layout");

  ImageRGBA8 image(static_cast<int>(width), static_cast<int>(height));
  std::vector<png_bytep> rows(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = image.at(0, static_cast<int>(y));
  if (!decodeRows(s.png, rows.data())) throw InputError(path, "malformed PNG: " + describe(state));
  return image;
}

}  // namespace

ImageRGBA8 readPng(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a PNG");
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) throw InputError(path, std::string("cannot open PNG: ") + std::strerror(errno));
  return decodePng(file, path);
}

ImageRGBA8 decodePngBytes(const std::vector<std::uint8_t>& bytes, const std::string& name) {
  if (bytes.empty()) throw InputError(name, "not a PNG file (empty)");
  // fmemopen reads the buffer in place (mode "rb" does not write to it).
  FilePtr file(::fmemopen(const_cast<std::uint8_t*>(bytes.data()), bytes.size(), "rb"));
  if (!file) throw InputError(name, std::string("cannot read PNG: ") + std::strerror(errno));
  return decodePng(file, name);
}

}  // namespace crumple::exporters
