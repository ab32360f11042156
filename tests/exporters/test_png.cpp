#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/core/crc32.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/png.hpp"
#include "temp_dir.hpp"

namespace crumple::exporters {
namespace {

using test::readBytes;
using test::writeBytes;
using Bytes = std::vector<std::uint8_t>;

ImageRGBA8 makeImage(int w, int h) {
  ImageRGBA8 image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = image.at(x, y);
      p[0] = static_cast<std::uint8_t>(x * 7 + y);
      p[1] = static_cast<std::uint8_t>(y * 11);
      p[2] = static_cast<std::uint8_t>((x * y) ^ 0x5A);
      p[3] = static_cast<std::uint8_t>((x + y) % 3 == 0 ? 0 : (x + y) % 3 == 1 ? 255 : x * 13);
    }
  return image;
}

bool containsBytes(const Bytes& haystack, const std::string& needle) {
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end()) !=
         haystack.end();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// --- A minimal PNG encoder (stored deflate blocks) for decoder tests -------

void putBE32(Bytes& out, std::uint32_t v) {
  for (int k = 3; k >= 0; --k) out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

void putChunk(Bytes& out, const std::string& type, const Bytes& data) {
  putBE32(out, static_cast<std::uint32_t>(data.size()));
  Bytes body(type.begin(), type.end());
  body.insert(body.end(), data.begin(), data.end());
  out.insert(out.end(), body.begin(), body.end());
  putBE32(out, crumple::crc32(body.data(), body.size()));
}

Bytes zlibStored(const Bytes& raw) {
  Bytes out = {0x78, 0x01};
  std::size_t pos = 0;
  do {
    const std::size_t n = std::min<std::size_t>(raw.size() - pos, 65535);
    out.push_back(pos + n == raw.size() ? 1 : 0);
    out.push_back(static_cast<std::uint8_t>(n));
    out.push_back(static_cast<std::uint8_t>(n >> 8));
    out.push_back(static_cast<std::uint8_t>(~n));
    out.push_back(static_cast<std::uint8_t>(~n >> 8));
    out.insert(out.end(), raw.begin() + pos, raw.begin() + pos + n);
    pos += n;
  } while (pos < raw.size());
  std::uint32_t a = 1, b = 0;
  for (std::uint8_t c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  putBE32(out, (b << 16) | a);
  return out;
}

// rows: packed scanlines without the filter byte (filter 0 is added).
Bytes makePng(int w, int h, int bitDepth, int colorType, const std::vector<Bytes>& rows,
              const std::vector<std::pair<std::string, Bytes>>& extra = {}) {
  Bytes out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  Bytes ihdr;
  putBE32(ihdr, static_cast<std::uint32_t>(w));
  putBE32(ihdr, static_cast<std::uint32_t>(h));
  ihdr.insert(ihdr.end(),
              {static_cast<std::uint8_t>(bitDepth), static_cast<std::uint8_t>(colorType), 0, 0, 0});
  putChunk(out, "IHDR", ihdr);
  for (const auto& [type, data] : extra) putChunk(out, type, data);
  Bytes raw;
  for (const auto& row : rows) {
    raw.push_back(0);
    raw.insert(raw.end(), row.begin(), row.end());
  }
  putChunk(out, "IDAT", zlibStored(raw));
  putChunk(out, "IEND", {});
  return out;
}

void expectPixel(const ImageRGBA8& image, int x, int y, std::array<int, 4> rgba) {
  const std::uint8_t* p = image.at(x, y);
  EXPECT_EQ((std::array<int, 4>{p[0], p[1], p[2], p[3]}), rgba) << "pixel " << x << "," << y;
}

class PngTest : public test::TempDirTest {};

TEST_F(PngTest, RoundTripIsExact) {
  const ImageRGBA8 image = makeImage(37, 23);
  const std::string path = file("frame.png");
  writePng(path, image);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const ImageRGBA8 back = readPng(path);
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.pixels, image.pixels);
}

TEST_F(PngTest, IdenticalImagesGiveIdenticalBytes) {
  const ImageRGBA8 image = makeImage(64, 48);
  writePng(file("a.png"), image);
  writePng(file("b.png"), image);
  const Bytes a = readBytes(file("a.png"));
  EXPECT_EQ(a, readBytes(file("b.png")));
  writePng(file("a.png"), image);  // overwriting an existing file
  EXPECT_EQ(readBytes(file("a.png")), a);
  EXPECT_TRUE(containsBytes(a, "sRGB"));
  EXPECT_FALSE(containsBytes(a, "tIME"));
}

TEST_F(PngTest, UnwritableFolderIsAnInputErrorAndLeavesNoFile) {
  const ImageRGBA8 image = makeImage(4, 4);
  const std::string missing = file("no/such/folder/frame.png");
  try {
    writePng(missing, image);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), missing)) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(missing));
  EXPECT_FALSE(std::filesystem::exists(missing + ".tmp"));

  // A "folder" that is a regular file (fails even for root).
  writeBytes(file("plain"), {1, 2, 3});
  const std::string underFile = file("plain/frame.png");
  EXPECT_THROW(writePng(underFile, image), InputError);
  EXPECT_EQ(readBytes(file("plain")), (Bytes{1, 2, 3}));

  // A folder without write permission (root ignores permissions).
  if (::geteuid() != 0) {
    const auto locked = dir() / "locked";
    std::filesystem::create_directory(locked);
    std::filesystem::permissions(
        locked, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const std::string path = (locked / "frame.png").string();
    EXPECT_THROW(writePng(path, image), InputError);
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
    std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
  }
}

TEST_F(PngTest, InvalidImageIsRejected) {
  ImageRGBA8 image(3, 3);
  image.pixels.pop_back();
  EXPECT_THROW(writePng(file("bad.png"), image), std::invalid_argument);
  EXPECT_THROW(writePng(file("empty.png"), ImageRGBA8()), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(file("bad.png.tmp")));
}

TEST_F(PngTest, MissingOrMalformedFilesAreInputErrors) {
  const std::string missing = file("missing.png");
  try {
    readPng(missing);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), missing)) << e.what();
  }
  EXPECT_THROW(readPng(dir().string()), InputError);

  writeBytes(file("text.png"), {'h', 'e', 'l', 'l', 'o'});
  EXPECT_THROW(readPng(file("text.png")), InputError);

  writePng(file("good.png"), makeImage(50, 40));
  const Bytes good = readBytes(file("good.png"));
  for (std::size_t cut : {std::size_t{8}, std::size_t{20}, good.size() / 2, good.size() - 13}) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    writeBytes(file("cut.png"), Bytes(good.begin(), good.begin() + cut));
    try {
      readPng(file("cut.png"));
      FAIL() << "no InputError";
    } catch (const InputError& e) {
      EXPECT_TRUE(contains(e.what(), file("cut.png"))) << e.what();
    }
  }
  Bytes flipped = good;
  flipped[good.size() / 2] ^= 0xFF;  // inside IDAT: CRC or zlib error
  writeBytes(file("flipped.png"), flipped);
  EXPECT_THROW(readPng(file("flipped.png")), InputError);
}

TEST_F(PngTest, OtherFormatsAreConvertedToRgba8) {
  // 8-bit grey.
  writeBytes(file("grey.png"), makePng(2, 1, 8, 0, {{0x10, 0xF0}}));
  ImageRGBA8 img = readPng(file("grey.png"));
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 1);
  expectPixel(img, 0, 0, {0x10, 0x10, 0x10, 255});
  expectPixel(img, 1, 0, {0xF0, 0xF0, 0xF0, 255});

  // 1-bit grey.
  writeBytes(file("bits.png"), makePng(3, 1, 1, 0, {{0b10100000}}));
  img = readPng(file("bits.png"));
  expectPixel(img, 0, 0, {255, 255, 255, 255});
  expectPixel(img, 1, 0, {0, 0, 0, 255});
  expectPixel(img, 2, 0, {255, 255, 255, 255});

  // 8-bit RGB, two rows.
  writeBytes(file("rgb.png"), makePng(1, 2, 8, 2, {{1, 2, 3}, {4, 5, 6}}));
  img = readPng(file("rgb.png"));
  ASSERT_EQ(img.height, 2);
  expectPixel(img, 0, 0, {1, 2, 3, 255});
  expectPixel(img, 0, 1, {4, 5, 6, 255});

  // Palette with transparency.
  writeBytes(file("palette.png"),
             makePng(3, 1, 8, 3, {{0, 1, 2}},
                     {{"PLTE", {10, 20, 30, 40, 50, 60, 70, 80, 90}}, {"tRNS", {0, 128}}}));
  img = readPng(file("palette.png"));
  expectPixel(img, 0, 0, {10, 20, 30, 0});
  expectPixel(img, 1, 0, {40, 50, 60, 128});
  expectPixel(img, 2, 0, {70, 80, 90, 255});

  // 16-bit grey + alpha (multiples of 257 scale exactly).
  writeBytes(file("ga16.png"), makePng(1, 1, 16, 4, {{0x80, 0x80, 0xFF, 0xFF}}));
  img = readPng(file("ga16.png"));
  expectPixel(img, 0, 0, {0x80, 0x80, 0x80, 0xFF});

  // 16-bit RGBA.
  writeBytes(file("rgba16.png"),
             makePng(1, 1, 16, 6, {{0x00, 0x00, 0x12, 0x12, 0xFF, 0xFF, 0x34, 0x34}}));
  img = readPng(file("rgba16.png"));
  expectPixel(img, 0, 0, {0x00, 0x12, 0xFF, 0x34});
}

}  // namespace
}  // namespace crumple::exporters
