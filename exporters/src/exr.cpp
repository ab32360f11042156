// OpenEXR through the OpenEXR 3 library: RgbaOutputFile into memory (so that
// every file-system error is ours to detect and report), InputFile with a
// float FrameBuffer for reading.
#include "crumple/exporters/exr.hpp"

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgba.h>
#include <ImfRgbaFile.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "image_write.hpp"

namespace crumple::exporters {
namespace {

constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 28;

// An Imf::OStream over a growable byte buffer (OpenEXR seeks back to write the
// line offset table when the file is closed).
class MemoryOStream final : public Imf::OStream {
 public:
  explicit MemoryOStream(const std::string& name) : Imf::OStream(name.c_str()) {}
  // Writes n bytes at the current position, growing the buffer.
  void write(const char c[], int n) override {
    const std::size_t end = pos_ + static_cast<std::size_t>(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(bytes_.data() + pos_, c, static_cast<std::size_t>(n));
    pos_ = end;
  }
  // The current write position.
  std::uint64_t tellp() override { return pos_; }
  // Moves the write position (OpenEXR only seeks back within what it wrote).
  void seekp(std::uint64_t pos) override { pos_ = static_cast<std::size_t>(pos); }
  // The file written so far.
  const std::vector<char>& bytes() const { return bytes_; }

 private:
  std::vector<char> bytes_;
  std::size_t pos_ = 0;
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

// A pixel value as a half: clamped to +-kExrHalfMax, NaN kept.
Imath::half toHalf(float v) {
  if (std::isnan(v)) return Imath::half(v);
  return Imath::half(std::clamp(v, -kExrHalfMax, kExrHalfMax));
}

// Checks `extra` against the image (std::invalid_argument).
void checkExtraChannels(const std::string& path, const ImageRGBAF& image,
                        const ImageChannels& extra) {
  if (extra.width != image.width || extra.height != image.height)
    throw std::invalid_argument(path + ": EXR channels of " + std::to_string(extra.width) + "x" +
                                std::to_string(extra.height) + " beside an image of " +
                                std::to_string(image.width) + "x" + std::to_string(image.height));
  const std::size_t n = static_cast<std::size_t>(image.width) * image.height;
  std::vector<std::string> names = {"R", "G", "B", "A"};
  for (const ImageChannel& c : extra.channels) {
    if (c.name.empty()) throw std::invalid_argument(path + ": an EXR channel without a name");
    if (std::find(names.begin(), names.end(), c.name) != names.end())
      throw std::invalid_argument(path + ": EXR channel '" + c.name + "' given twice");
    if (c.pixels.size() != n)
      throw std::invalid_argument(path + ": EXR channel '" + c.name + "' has " +
                                  std::to_string(c.pixels.size()) + " pixels, not " +
                                  std::to_string(n));
    names.push_back(c.name);
  }
}

// Encodes the image and `extra` as a complete EXR file in memory (the
// general OutputFile: RgbaOutputFile writes R, G, B, A only).
std::vector<char> encodeChannels(const std::string& path, const ImageRGBAF& image,
                                 const ImageChannels& extra) {
  const int w = image.width, h = image.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.lineOrder() = Imf::INCREASING_Y;
  std::vector<std::vector<Imath::half>> halves;
  halves.reserve(4 + extra.channels.size());
  Imf::FrameBuffer fb;
  const Imath::Box2i dw = header.dataWindow();
  const auto addHalf = [&](const char* name, const float* values, std::size_t stride) {
    std::vector<Imath::half>& hv = halves.emplace_back(n);
    for (std::size_t i = 0; i < n; ++i) hv[i] = toHalf(values[i * stride]);
    header.channels().insert(name, Imf::Channel(Imf::HALF));
    fb.insert(name, Imf::Slice::Make(Imf::HALF, hv.data(), dw, sizeof(Imath::half),
                                     sizeof(Imath::half) * static_cast<std::size_t>(w)));
  };
  const char* rgba[4] = {"R", "G", "B", "A"};
  for (int k = 0; k < 4; ++k) addHalf(rgba[k], image.pixels.data() + k, 4);
  for (const ImageChannel& c : extra.channels) {
    if (!c.fullFloat) {
      addHalf(c.name.c_str(), c.pixels.data(), 1);
      continue;
    }
    header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    fb.insert(c.name, Imf::Slice::Make(Imf::FLOAT, c.pixels.data(), dw, sizeof(float),
                                       sizeof(float) * static_cast<std::size_t>(w)));
  }
  MemoryOStream stream(path);
  {
    Imf::OutputFile file(stream, header, 0);  // one thread, as encode()
    file.setFrameBuffer(fb);
    file.writePixels(h);
  }
  return stream.bytes();
}

// Encodes the image as a complete EXR file in memory.
std::vector<char> encode(const std::string& path, const ImageRGBAF& image) {
  const int w = image.width, h = image.height;
  std::vector<Imf::Rgba> pixels(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const float* p = image.pixels.data() + 4 * i;
    pixels[i] = Imf::Rgba(toHalf(p[0]), toHalf(p[1]), toHalf(p[2]), toHalf(p[3]));
  }
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.lineOrder() = Imf::INCREASING_Y;
  MemoryOStream stream(path);
  {
    // One thread: no thread pool is started for a single file (the bytes
    // would be the same either way).
    Imf::RgbaOutputFile file(stream, header, Imf::WRITE_RGBA, 0);
    file.setFrameBuffer(pixels.data(), 1, static_cast<std::size_t>(w));
    file.writePixels(h);
  }  // the destructor writes the line offset table
  return stream.bytes();
}

}  // namespace

namespace {

// Writes the encoded bytes to PATH.tmp and renames it over PATH.
void writeBytes(const std::string& path, const std::vector<char>& bytes) {
  const std::string tmp = path + ".tmp";
  FilePtr file(std::fopen(tmp.c_str(), "wb"));
  if (!file) throw InputError(path, std::string("cannot write EXR: ") + std::strerror(errno));
  std::string problem;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
    problem = std::strerror(errno);
  finishAtomicWrite(file.release(), tmp, path, "EXR", problem);
}

}  // namespace

// Atomic EXR write: encode in memory, write PATH.tmp, rename.
void writeExr(const std::string& path, const ImageRGBAF& image) {
  checkImageToWrite(path, "EXR", image, "floats");
  std::vector<char> bytes;
  try {
    bytes = encode(path, image);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot encode EXR: " + e.what());
  }
  writeBytes(path, bytes);
}

void writeExr(const std::string& path, const ImageRGBAF& image, const ImageChannels& extra) {
  if (extra.channels.empty()) return writeExr(path, image);
  checkImageToWrite(path, "EXR", image, "floats");
  checkExtraChannels(path, image, extra);
  std::vector<char> bytes;
  try {
    bytes = encodeChannels(path, image, extra);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot encode EXR: " + e.what());
  }
  writeBytes(path, bytes);
}

namespace {

// Opens an EXR file for reading and checks its data window (at most
// kMaxPixels) and completeness, then returns body(file, dataWindow, w, h);
// every failure is an InputError naming the file.
template <class Body>
auto readChecked(const std::string& path, Body body) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not an EXR");
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "cannot open EXR: no such file");
  try {
    Imf::InputFile file(path.c_str(), 0);
    const Imath::Box2i dw = file.header().dataWindow();
    const std::int64_t w = static_cast<std::int64_t>(dw.max.x) - dw.min.x + 1;
    const std::int64_t h = static_cast<std::int64_t>(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0 ||
        static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) > kMaxPixels)
      throw InputError(path, "EXR data window too large or empty (" + std::to_string(w) + "x" +
                                 std::to_string(h) + ")");
    if (!file.isComplete()) throw InputError(path, "truncated EXR (missing pixel blocks)");
    return body(file, dw, static_cast<int>(w), static_cast<int>(h));
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path, std::string("cannot read EXR: ") + e.what());
  }
}

}  // namespace

// EXR read through a float FrameBuffer over the data window.
ImageRGBAF readExr(const std::string& path) {
  return readChecked(path, [&](Imf::InputFile& file, const Imath::Box2i& dw, int w, int h) {
    for (const char* name : {"R", "G", "B"})
      if (!file.header().channels().findChannel(name))
        throw InputError(path, std::string("EXR has no '") + name + "' channel");
    ImageRGBAF image(w, h);
    const std::size_t xStride = 4 * sizeof(float);
    const std::size_t yStride = xStride * static_cast<std::size_t>(w);
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int k = 0; k < 4; ++k)
      fb.insert(names[k], Imf::Slice::Make(Imf::FLOAT, image.pixels.data() + k, dw, xStride,
                                           yStride, 1, 1, k == 3 ? 1.0 : 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return image;
  });
}

ImageChannels readExrChannels(const std::string& path) {
  return readChecked(path, [&](Imf::InputFile& file, const Imath::Box2i& dw, int w, int h) {
    ImageChannels out;
    out.width = w;
    out.height = h;
    const Imf::ChannelList& list = file.header().channels();
    for (auto it = list.begin(); it != list.end(); ++it) {
      ImageChannel& c = out.channels.emplace_back();
      c.name = it.name();
      c.fullFloat = it.channel().type != Imf::HALF;
      c.pixels.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0.0f);
    }
    Imf::FrameBuffer fb;
    for (ImageChannel& c : out.channels)
      fb.insert(c.name, Imf::Slice::Make(Imf::FLOAT, c.pixels.data(), dw, sizeof(float),
                                         sizeof(float) * static_cast<std::size_t>(w)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return out;
  });
}

}  // namespace crumple::exporters
