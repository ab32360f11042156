#pragma once
// The extension sub-blocks crumple writes (docs/PCACHE.md "Extension
// sub-blocks written by crumple"), on the core byte codec (byte_io.hpp):
// errors name the block, the record being read and the field
// (CorruptDataError). Internal to the cache library.
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/byte_io.hpp"
#include "crumple/core/error.hpp"

namespace crumple::cache::detail {

using Tag = ByteTag;

// Reads one sub-block: "pcache <block> sub-block: ..." in every message.
class SubBlockReader : public ByteReader {
 public:
  SubBlockReader(const Bytes& bytes, const char* block)
      : ByteReader(bytes, {std::string("pcache ") + block + " sub-block"}) {}
};

inline std::string tagName(const Tag& tag) { return std::string(tag.data(), tag.size()); }

// The one block with `tag`, or null; two are malformed.
inline const ExtensionBlock* findOneBlock(const std::vector<ExtensionBlock>& blocks,
                                          const Tag& tag) {
  const ExtensionBlock* found = nullptr;
  for (const auto& b : blocks) {
    if (b.tag != tag) continue;
    if (found)
      throw CorruptDataError("pcache " + tagName(tag) + " sub-block: present more than once");
    found = &b;
  }
  return found;
}

// A block's list of records: a u32 count, then each record. `problem`
// (empty when valid) is checked before a record is written, as
// std::invalid_argument "<encoder>: <record> <i>: <problem>".
template <typename T, typename Problem, typename WriteOne>
void writeRecords(ByteWriter& w, const std::vector<T>& records, const char* encoder,
                  const char* record, Problem problem, WriteOne writeOne) {
  w.count32(records.size(), record);
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (const std::string p = problem(records[i]); !p.empty())
      throw std::invalid_argument(std::string(encoder) + ": " + record + " " + std::to_string(i) +
                                  ": " + p);
    writeOne(records[i]);
  }
}

// Reads what writeRecords wrote: records of at least minBytes each, each read
// by readOne with the reader naming it ("<record> <i>: ...").
template <typename T, typename ReadOne>
std::vector<T> readRecords(SubBlockReader& r, std::size_t minBytes, const char* record,
                           ReadOne readOne) {
  std::vector<T> records(r.count32(minBytes, (std::string(record) + " count").c_str()));
  for (std::size_t i = 0; i < records.size(); ++i) {
    r.at(record, i);
    readOne(records[i]);
  }
  return records;
}

// The block with `tag` decoded by decode(reader), which must read it to its
// end; nullopt without one.
template <typename Decode>
auto decodeBlock(const std::vector<ExtensionBlock>& blocks, const Tag& tag, Decode decode)
    -> std::optional<decltype(decode(std::declval<SubBlockReader&>()))> {
  const ExtensionBlock* block = findOneBlock(blocks, tag);
  if (!block) return std::nullopt;
  const std::string name = tagName(tag);
  SubBlockReader r(block->data, name.c_str());
  auto decoded = decode(r);
  r.expectEnd();
  return decoded;
}

}  // namespace crumple::cache::detail
