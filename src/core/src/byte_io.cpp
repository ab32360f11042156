#include "crumple/core/byte_io.hpp"

#include <bit>
#include <limits>
#include <stdexcept>

#include "crumple/core/error.hpp"

namespace crumple {

static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8,
              "doubles are stored as IEEE-754 binary64");
static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4,
              "floats are stored as IEEE-754 binary32");

void ByteWriter::f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }

void ByteWriter::f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }

void ByteWriter::raw(const void* data, std::size_t n) {
  const auto* b = static_cast<const std::uint8_t*>(data);
  out_->insert(out_->end(), b, b + n);
}

void ByteWriter::count32(std::size_t n, const char* what) {
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error(std::string("too many ") + what + " (" + std::to_string(n) +
                            ") for a 32-bit count");
  u32(static_cast<std::uint32_t>(n));
}

void ByteWriter::str32(const std::string& s, const char* what) {
  count32(s.size(), what);
  raw(s.data(), s.size());
}

void ByteWriter::str64(const std::string& s) {
  count64(s.size());
  raw(s.data(), s.size());
}

ByteReader::ByteReader(std::span<const std::uint8_t> bytes, Naming naming)
    : bytes_(bytes), naming_(std::move(naming)) {}

void ByteReader::fail(const std::string& problem) const {
  std::string message = naming_.source.empty() ? "" : naming_.source + ": ";
  if (kind_) message += std::string(kind_) + " " + std::to_string(index_) + ": ";
  message += problem;
  if (naming_.byteOffsets) message += " (at byte " + std::to_string(pos_) + ")";
  throw CorruptDataError(message);
}

const std::uint8_t* ByteReader::take(std::size_t n, const char* field) {
  if (n > remaining()) fail(field ? std::string(field) + " truncated" : "truncated");
  const std::uint8_t* p = bytes_.data() + pos_;
  pos_ += n;
  return p;
}

std::uint64_t ByteReader::get(int n, const char* field) {
  const std::uint8_t* p = take(static_cast<std::size_t>(n), field);
  std::uint64_t v = 0;
  for (int k = 0; k < n; ++k) v |= static_cast<std::uint64_t>(p[k]) << (8 * k);
  return v;
}

float ByteReader::f32(const char* field) { return std::bit_cast<float>(u32(field)); }

double ByteReader::f64(const char* field) { return std::bit_cast<double>(u64(field)); }

bool ByteReader::boolean(const char* field) {
  const std::uint8_t b = u8(field);
  if (b > 1)
    fail((field ? std::string(field) + ": " : std::string()) + "a flag of " + std::to_string(b));
  return b == 1;
}

ByteTag ByteReader::tag(const char* field) {
  const std::uint8_t* p = take(4, field);
  return {static_cast<char>(p[0]), static_cast<char>(p[1]), static_cast<char>(p[2]),
          static_cast<char>(p[3])};
}

std::size_t ByteReader::checkedCount(std::uint64_t n, std::size_t minBytes,
                                     const char* field) const {
  if (minBytes > 0 && n > remaining() / minBytes)
    fail((field ? std::string(field) + " " : std::string("a count of ")) + std::to_string(n) +
         " runs past the end (" + std::to_string(remaining()) + " bytes left)");
  return static_cast<std::size_t>(n);
}

std::size_t ByteReader::count32(std::size_t minBytes, const char* field) {
  return checkedCount(u32(field), minBytes, field);
}

std::size_t ByteReader::count64(std::size_t minBytes, const char* field) {
  return checkedCount(u64(field), minBytes, field);
}

std::string ByteReader::str32(const char* field) {
  const std::size_t n = count32(1, field);
  const std::uint8_t* p = take(n, field);
  return std::string(reinterpret_cast<const char*>(p), n);
}

std::string ByteReader::str64(const char* field) {
  const std::size_t n = count64(1, field);
  const std::uint8_t* p = take(n, field);
  return std::string(reinterpret_cast<const char*>(p), n);
}

void ByteReader::expectEnd() {
  kind_ = nullptr;
  if (remaining() != 0) fail(std::to_string(remaining()) + " trailing bytes");
}

}  // namespace crumple
