// OpenEXR export and import: round trip within half precision, atomic
// writes, deterministic bytes, errors naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/exporters/exr.hpp"
#include "temp_dir.hpp"

namespace crumple::exporters {
namespace {

using test::readBytes;
using test::writeBytes;
using Bytes = std::vector<std::uint8_t>;

class Exr : public test::TempDirTest {};

// Linear premultiplied test pattern with smooth values, an alpha ramp and
// some extremes.
ImageRGBAF makeImage(int w, int h) {
  ImageRGBAF img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = img.at(x, y);
      const float a = static_cast<float>(x + 1) / static_cast<float>(w);
      p[0] = a * (0.1f + 0.013f * static_cast<float>(x));
      p[1] = a * 0.37f * static_cast<float>(y) / static_cast<float>(h);
      p[2] = a * std::sin(0.7f * static_cast<float>(x * y)) * 3.0f;  // negative too
      p[3] = a;
    }
  return img;
}

// Where needle first occurs in bytes at or after from (npos if nowhere).
std::size_t find(const Bytes& bytes, const std::string& needle, std::size_t from = 0) {
  const auto it = std::search(bytes.begin() + static_cast<std::ptrdiff_t>(from), bytes.end(),
                              needle.begin(), needle.end());
  return it == bytes.end() ? std::string::npos : static_cast<std::size_t>(it - bytes.begin());
}

// The little-endian 32-bit integer at `at`.
std::int32_t le32(const Bytes& b, std::size_t at) {
  return static_cast<std::int32_t>(b[at] | (b[at + 1] << 8) | (b[at + 2] << 16) |
                                   (static_cast<std::uint32_t>(b[at + 3]) << 24));
}

// Whether text contains part.
bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Half precision: relative 2^-11 for normal values, 2^-25 absolute below.
void expectHalfClose(float actual, float expected) {
  EXPECT_NEAR(actual, expected, std::max(std::abs(expected) * 0x1p-11f, 0x1p-25f));
}

TEST_F(Exr, RoundTripWithinHalfPrecision) {
  const ImageRGBAF img = makeImage(13, 7);
  const std::string path = file("a.exr");
  writeExr(path, img);
  const ImageRGBAF back = readExr(path);
  ASSERT_EQ(back.width, 13);
  ASSERT_EQ(back.height, 7);
  bool anyInexact = false;
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    expectHalfClose(back.pixels[i], img.pixels[i]);
    anyInexact |= back.pixels[i] != img.pixels[i];
  }
  EXPECT_TRUE(anyInexact);  // really stored as half
  // Row order: top row first.
  expectHalfClose(back.at(12, 6)[1], 0.37f * 6.0f / 7.0f);
}

TEST_F(Exr, ExtremesAreClampedToTheHalfRange) {
  ImageRGBAF img(4, 1);
  const float inf = std::numeric_limits<float>::infinity();
  const float values[16] = {70000.0f,      -1e9f, inf,    -inf,  65504.0f, 1e-7f, 0.0f, 1.0f,
                            std::nanf(""), 2.5f,  1e-30f, -0.0f, 1000.5f,  3.0f,  0.5f, 0.25f};
  std::copy(std::begin(values), std::end(values), img.pixels.begin());
  writeExr(file("x.exr"), img);
  const ImageRGBAF back = readExr(file("x.exr"));
  EXPECT_EQ(back.pixels[0], kExrHalfMax);
  EXPECT_EQ(back.pixels[1], -kExrHalfMax);
  EXPECT_EQ(back.pixels[2], kExrHalfMax);
  EXPECT_EQ(back.pixels[3], -kExrHalfMax);
  EXPECT_EQ(back.pixels[4], 65504.0f);
  expectHalfClose(back.pixels[5], 1e-7f);
  EXPECT_TRUE(std::isnan(back.pixels[8]));
  EXPECT_EQ(back.pixels[10], 0.0f);  // below the smallest subnormal
  EXPECT_EQ(back.pixels[12], 1000.5f);
  EXPECT_EQ(back.pixels[15], 0.25f);
}

TEST_F(Exr, IdenticalBytesAndNoTimestamp) {
  const ImageRGBAF img = makeImage(40, 33);  // more than one 16-line ZIP block
  writeExr(file("a.exr"), img);
  writeExr(file("b.exr"), img);
  const Bytes a = readBytes(file("a.exr")), b = readBytes(file("b.exr"));
  ASSERT_GT(a.size(), 100u);
  EXPECT_EQ(a, b);
  // Magic number, and none of the standard time or owner attributes.
  EXPECT_EQ(le32(a, 0), 20000630);
  for (const char* attr : {"capDate", "utcOffset", "owner", "comments", "framesPerSecond"})
    EXPECT_EQ(find(a, attr), std::string::npos) << attr;
  // ZIP compression (3).
  const std::size_t comp = find(a, std::string("compression\0compression\0", 24));
  ASSERT_NE(comp, std::string::npos);
  EXPECT_EQ(le32(a, comp + 24), 1);
  EXPECT_EQ(a[comp + 28], 3);
  // Channels A, B, G, R, all HALF (1).
  const std::size_t ch = find(a, std::string("channels\0chlist\0", 16));
  ASSERT_NE(ch, std::string::npos);
  std::size_t at = ch + 16 + 4;
  for (const char* name : {"A", "B", "G", "R"}) {
    ASSERT_EQ(a[at], name[0]);
    ASSERT_EQ(a[at + 1], 0);
    EXPECT_EQ(le32(a, at + 2), 1) << name;
    at += 2 + 16;
  }
  // A different image gives different bytes.
  ImageRGBAF other = img;
  other.at(3, 30)[0] += 0.25f;
  writeExr(file("c.exr"), other);
  EXPECT_NE(readBytes(file("c.exr")), a);
  // Compression works: far smaller than 8 bytes per pixel for a flat image.
  writeExr(file("flat.exr"), ImageRGBAF(64, 64));
  EXPECT_LT(readBytes(file("flat.exr")).size(), 64u * 64u * 8u / 10u);
}

TEST_F(Exr, AtomicWrite) {
  const std::string path = file("frame.exr");
  writeExr(path, makeImage(8, 8));
  writeExr(path, makeImage(9, 4));  // replaces the file
  EXPECT_EQ(readExr(path).width, 9);
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir()))
    names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"frame.exr"});  // no .tmp left behind

  // Into a missing folder: InputError naming the file, nothing created.
  const std::string missing = (dir() / "no" / "such" / "dir" / "f.exr").string();
  try {
    writeExr(missing, makeImage(2, 2));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), missing)) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir() / "no"));

  // A failed write leaves the previous file untouched.
  const Bytes before = readBytes(path);
  std::filesystem::create_directory(path + ".tmp");  // fopen of the temp file fails
  EXPECT_THROW(writeExr(path, makeImage(3, 3)), InputError);
  EXPECT_EQ(readBytes(path), before);

  EXPECT_THROW(writeExr(file("bad.exr"), ImageRGBAF()), std::invalid_argument);
  ImageRGBAF inconsistent(2, 2);
  inconsistent.pixels.pop_back();
  EXPECT_THROW(writeExr(file("bad.exr"), inconsistent), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(file("bad.exr")));
}

// readExr(path) must throw InputError mentioning path and `part`.
void expectReadError(const std::string& path, const std::string& part = "") {
  try {
    readExr(path);
    ADD_FAILURE() << "expected InputError for " << path;
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), path)) << e.what();
    EXPECT_TRUE(contains(e.what(), part)) << e.what();
  }
}

TEST_F(Exr, ReadErrorsNameTheFile) {
  expectReadError(file("missing.exr"), "no such file");
  expectReadError(dir().string(), "directory");

  Bytes garbage(500);
  for (std::size_t i = 0; i < garbage.size(); ++i)
    garbage[i] = static_cast<std::uint8_t>(i * 37 + 11);
  writeBytes(file("garbage.exr"), garbage);
  expectReadError(file("garbage.exr"));
  writeBytes(file("empty.exr"), {});
  expectReadError(file("empty.exr"));

  // A valid file cut short.
  writeExr(file("full.exr"), makeImage(40, 40));
  Bytes full = readBytes(file("full.exr"));
  for (std::size_t keep : {full.size() / 2, std::size_t{40}}) {
    writeBytes(file("cut.exr"), Bytes(full.begin(), full.begin() + static_cast<long>(keep)));
    expectReadError(file("cut.exr"));
  }
}

// Renames a channel in a written file's header (same length, sort order kept).
Bytes renameChannel(Bytes bytes, char from, char to) {
  const std::size_t ch = find(bytes, std::string("channels\0chlist\0", 16));
  EXPECT_NE(ch, std::string::npos);
  for (std::size_t at = ch + 20; bytes[at] != 0; at += 18)
    if (bytes[at] == static_cast<std::uint8_t>(from)) bytes[at] = static_cast<std::uint8_t>(to);
  return bytes;
}

TEST_F(Exr, ChannelRequirements) {
  const ImageRGBAF img = makeImage(6, 5);
  writeExr(file("ok.exr"), img);
  const Bytes ok = readBytes(file("ok.exr"));

  // No R (renamed S): rejected, naming the channel.
  writeBytes(file("noR.exr"), renameChannel(ok, 'R', 'S'));
  expectReadError(file("noR.exr"), "'R'");

  // No A (renamed 0): read as opaque.
  writeBytes(file("noA.exr"), renameChannel(ok, 'A', '0'));
  const ImageRGBAF opaque = readExr(file("noA.exr"));
  ASSERT_EQ(opaque.width, 6);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      EXPECT_EQ(opaque.at(x, y)[3], 1.0f);
      expectHalfClose(opaque.at(x, y)[0], img.at(x, y)[0]);
    }
}

}  // namespace
}  // namespace crumple::exporters

namespace crumple::exporters {
namespace {

// Channels beside RGBA: a half and a 32-bit one per name kind.
ImageChannels makeChannels(int w, int h) {
  ImageChannels c;
  c.width = w;
  c.height = h;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  for (const char* name : {"Z", "N.X", "IndexOB.X"}) {
    ImageChannel& ch = c.channels.emplace_back();
    ch.name = name;
    ch.fullFloat = std::string(name) != "N.X";
    for (std::size_t i = 0; i < n; ++i)
      ch.pixels.push_back(ch.fullFloat ? 1e10f / static_cast<float>(i + 3) + 0.123456789f
                                       : 0.3f + 0.001f * static_cast<float>(i));
  }
  return c;
}

class ExrChannels : public test::TempDirTest {};

TEST_F(ExrChannels, ExtraChannelsRoundTripAtTheirPrecision) {
  const ImageRGBAF img = makeImage(21, 19);  // two ZIP blocks
  const ImageChannels extra = makeChannels(21, 19);
  const std::string path = file("layers.exr");
  writeExr(path, img, extra);
  const ImageChannels back = readExrChannels(path);
  ASSERT_EQ(back.width, 21);
  ASSERT_EQ(back.height, 19);
  std::vector<std::string> names;
  for (const ImageChannel& c : back.channels) names.push_back(c.name);
  // The file's (alphabetical) order.
  EXPECT_EQ(names, (std::vector<std::string>{"A", "B", "G", "IndexOB.X", "N.X", "R", "Z"}));
  for (const ImageChannel& c : extra.channels) {
    const ImageChannel* b = back.find(c.name);
    ASSERT_NE(b, nullptr) << c.name;
    EXPECT_EQ(b->fullFloat, c.fullFloat) << c.name;
    for (std::size_t i = 0; i < c.pixels.size(); ++i) {
      if (c.fullFloat)
        ASSERT_EQ(b->pixels[i], c.pixels[i]) << c.name << " " << i;  // 32-bit: exact
      else
        expectHalfClose(b->pixels[i], c.pixels[i]);
    }
  }
  // RGBA as writeExr stores it.
  writeExr(file("plain.exr"), img);
  const ImageRGBAF plain = readExr(file("plain.exr")), rgba = readExr(path);
  EXPECT_EQ(plain.pixels, rgba.pixels);
}

TEST_F(ExrChannels, NoExtraChannelsIsWriteExrByteForByteAndBytesAreDeterministic) {
  const ImageRGBAF img = makeImage(17, 5);
  writeExr(file("a.exr"), img);
  writeExr(file("b.exr"), img, ImageChannels{});
  EXPECT_EQ(readBytes(file("a.exr")), readBytes(file("b.exr")));
  writeExr(file("c.exr"), img, makeChannels(17, 5));
  writeExr(file("d.exr"), img, makeChannels(17, 5));
  EXPECT_EQ(readBytes(file("c.exr")), readBytes(file("d.exr")));
  EXPECT_NE(readBytes(file("a.exr")), readBytes(file("c.exr")));
}

TEST_F(ExrChannels, InconsistentChannelsAreRejectedAndNothingIsWritten) {
  const ImageRGBAF img = makeImage(8, 4);
  const auto rejects = [&](ImageChannels extra, const std::string& what) {
    const std::string path = file("bad.exr");
    try {
      writeExr(path, img, extra);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_TRUE(contains(e.what(), what)) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(path));
  };
  ImageChannels wrongSize = makeChannels(8, 5);
  rejects(wrongSize, "8x5");
  ImageChannels shortChannel = makeChannels(8, 4);
  shortChannel.channels[1].pixels.pop_back();
  rejects(shortChannel, "'N.X' has 31 pixels");
  ImageChannels clash = makeChannels(8, 4);
  clash.channels[0].name = "R";
  rejects(clash, "'R' given twice");
  ImageChannels twice = makeChannels(8, 4);
  twice.channels[2].name = "Z";
  rejects(twice, "'Z' given twice");
  ImageChannels unnamed = makeChannels(8, 4);
  unnamed.channels[0].name.clear();
  rejects(unnamed, "without a name");
}

TEST_F(ExrChannels, ReadingChecksTheFileAsReadExrDoes) {
  EXPECT_THROW(readExrChannels(file("missing.exr")), InputError);
  EXPECT_THROW(readExrChannels(dir().string()), InputError);
}

}  // namespace
}  // namespace crumple::exporters
