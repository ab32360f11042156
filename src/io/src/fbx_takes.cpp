#include "fbx_takes.hpp"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "crumple/core/error.hpp"

namespace crumple::io::detail {

namespace {

constexpr int kMaxDepth = 64;                         // nesting of node records
constexpr std::uint64_t kMaxArrayBytes = 1ull << 28;  // one decoded KeyTime array

// One property of a node record: integers (and KeyTime arrays) and strings
// are kept, everything else only skipped.
struct Prop {
  char type = 0;
  std::int64_t integer = 0;
  std::string text;
  std::vector<std::int64_t> integers;  // the KeyTime array
};

struct Node {
  std::string name;
  std::vector<Prop> props;
  std::vector<Node> children;
};

// FBX binary: little-endian node records (endOffset, property count,
// property list length, name), properties, nested records ended by a null
// record; 32-bit header fields before version 7500, 64-bit from it.
class BinaryReader {
 public:
  BinaryReader(const std::string& path, std::vector<unsigned char> bytes)
      : path_(path), b_(std::move(bytes)) {}

  std::vector<Node> read() {
    version_ = static_cast<std::uint32_t>(uint(23, 4));
    std::vector<Node> top;
    std::uint64_t pos = 27;
    while (pos < b_.size()) {
      Node n;
      if (!record(pos, b_.size(), 0, n)) break;
      top.push_back(std::move(n));
    }
    return top;
  }

 private:
  [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
    throw InputError(path_, "FBX record at byte " + std::to_string(at) + ": " + what);
  }

  std::uint64_t uint(std::uint64_t at, int size) const {
    if (at + static_cast<std::uint64_t>(size) > b_.size()) fail(at, "ends past the file");
    std::uint64_t v = 0;
    for (int i = size - 1; i >= 0; --i) v = v << 8 | b_[at + static_cast<std::uint64_t>(i)];
    return v;
  }

  // Reads the record at pos (within `end`) into n and moves pos past it;
  // false at a null record (the end of a list).
  bool record(std::uint64_t& pos, std::uint64_t end, int depth, Node& n) {
    if (depth > kMaxDepth) fail(pos, "nested deeper than " + std::to_string(kMaxDepth));
    const int w = version_ >= 7500 ? 8 : 4;
    const std::uint64_t start = pos;
    const std::uint64_t endOffset = uint(pos, w), count = uint(pos + w, w);
    const std::uint64_t listLength = uint(pos + 2 * w, w);
    const std::uint64_t nameLength = uint(pos + 3 * w, 1);
    if (endOffset == 0) {
      pos += 3 * static_cast<std::uint64_t>(w) + 1;
      return false;
    }
    if (endOffset <= start || endOffset > end) fail(start, "its end lies outside its parent");
    pos += 3 * static_cast<std::uint64_t>(w) + 1;
    if (pos + nameLength > endOffset) fail(start, "its name runs past its end");
    n.name.assign(reinterpret_cast<const char*>(&b_[pos]), nameLength);
    pos += nameLength;
    const std::uint64_t propsEnd = pos + listLength;
    if (listLength > endOffset - pos) fail(start, "its properties run past its end");
    for (std::uint64_t i = 0; i < count; ++i) n.props.push_back(property(pos, propsEnd, n.name));
    if (pos != propsEnd) fail(start, "its property list length does not match its properties");
    while (pos < endOffset) {
      Node child;
      if (!record(pos, endOffset, depth + 1, child)) break;
      n.children.push_back(std::move(child));
    }
    pos = endOffset;
    return true;
  }

  Prop property(std::uint64_t& pos, std::uint64_t end, const std::string& owner) {
    const std::uint64_t at = pos;
    if (pos >= end) fail(at, "more properties than its list holds");
    Prop p;
    p.type = static_cast<char>(b_[pos++]);
    const auto scalar = [&](int size, bool keep) {
      if (pos + static_cast<std::uint64_t>(size) > end) fail(at, "a property runs past its list");
      if (keep) p.integer = static_cast<std::int64_t>(uint(pos, size));
      pos += static_cast<std::uint64_t>(size);
    };
    switch (p.type) {
      case 'Y':
        scalar(2, false);
        break;
      case 'C':
        scalar(1, false);
        break;
      case 'I':
        scalar(4, true);
        p.integer = static_cast<std::int32_t>(p.integer);
        break;
      case 'F':
        scalar(4, false);
        break;
      case 'D':
        scalar(8, false);
        break;
      case 'L':
        scalar(8, true);
        break;
      case 'S':
      case 'R': {
        const std::uint64_t length = uint(pos, 4);
        pos += 4;
        if (length > end - pos) fail(at, "a string runs past its list");
        if (p.type == 'S') p.text.assign(reinterpret_cast<const char*>(&b_[pos]), length);
        pos += length;
        break;
      }
      case 'f':
      case 'd':
      case 'l':
      case 'i':
      case 'b':
        array(pos, end, at, p, owner == "KeyTime" && p.type == 'l');
        break;
      default:
        fail(at, std::string("unknown property type '") + p.type + "'");
    }
    return p;
  }

  // An array property: u32 count, u32 encoding (0 raw, 1 zlib), u32 bytes.
  void array(std::uint64_t& pos, std::uint64_t end, std::uint64_t at, Prop& p, bool keep) {
    const std::uint64_t count = uint(pos, 4), encoding = uint(pos + 4, 4);
    const std::uint64_t bytes = uint(pos + 8, 4);
    pos += 12;
    if (bytes > end - pos) fail(at, "an array runs past its list");
    if (keep) {
      if (count * 8 > kMaxArrayBytes) fail(at, "a KeyTime array of " + std::to_string(count));
      std::vector<unsigned char> raw(count * 8);
      if (encoding == 0) {
        if (bytes != raw.size()) fail(at, "a KeyTime array's size does not match its count");
        std::copy_n(b_.begin() + static_cast<std::ptrdiff_t>(pos), bytes, raw.begin());
      } else if (encoding == 1) {
        uLongf out = static_cast<uLongf>(raw.size());
        if (uncompress(raw.data(), &out, &b_[pos], static_cast<uLong>(bytes)) != Z_OK ||
            out != raw.size())
          fail(at, "a compressed KeyTime array does not inflate to its count");
      } else {
        fail(at, "an array with unknown encoding " + std::to_string(encoding));
      }
      p.integers.resize(count);
      for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t v = 0;
        for (int k = 7; k >= 0; --k) v = v << 8 | raw[8 * i + static_cast<std::uint64_t>(k)];
        p.integers[i] = static_cast<std::int64_t>(v);
      }
    }
    pos += bytes;
  }

  std::string path_;
  std::vector<unsigned char> b_;
  std::uint32_t version_ = 0;
};

// FBX ASCII: `Name: value, value, ... { children }`, one node per line
// unless its value list goes on after a comma; strings in double quotes,
// arrays as `*N { a: v, v, ... }`, comments from ';' to the line's end.
class AsciiReader {
 public:
  AsciiReader(const std::string& path, std::string text) : path_(path), t_(std::move(text)) {}

  std::vector<Node> read() {
    std::vector<Node> top;
    skip();
    while (pos_ < t_.size()) {
      top.push_back(node(0));
      skip();
    }
    return top;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(path_, "FBX line " + std::to_string(line_) + ": " + what);
  }

  // Skips blanks and comments; true when it crossed a line break.
  bool skip() {
    bool newline = false;
    while (pos_ < t_.size()) {
      const char c = t_[pos_];
      if (c == '\n') {
        newline = true;
        ++line_;
        ++pos_;
      } else if (c == ' ' || c == '\t' || c == '\r') {
        ++pos_;
      } else if (c == ';') {
        while (pos_ < t_.size() && t_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
    return newline;
  }

  static bool nameChar(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '|' || c == '-';
  }

  std::string name() {
    const std::size_t from = pos_;
    while (pos_ < t_.size() && nameChar(t_[pos_])) ++pos_;
    if (pos_ == from || pos_ >= t_.size() || t_[pos_] != ':') fail("expected a node name and ':'");
    std::string out = t_.substr(from, pos_ - from);
    ++pos_;
    return out;
  }

  Node node(int depth) {
    if (depth > kMaxDepth) fail("nested deeper than " + std::to_string(kMaxDepth));
    Node n;
    n.name = name();
    bool newline = skip();
    while (!newline && pos_ < t_.size() && t_[pos_] != '{' && t_[pos_] != '}') {
      n.props.push_back(value(n.name));
      newline = skip();
      if (newline || pos_ >= t_.size() || t_[pos_] != ',') break;
      ++pos_;
      newline = false;
      skip();  // a list may go on on the next line after a comma
    }
    if (pos_ < t_.size() && t_[pos_] == '{') {
      ++pos_;
      skip();
      while (pos_ < t_.size() && t_[pos_] != '}') {
        n.children.push_back(node(depth + 1));
        skip();
      }
      if (pos_ >= t_.size()) fail("'" + n.name + "' has no closing '}'");
      ++pos_;
    }
    return n;
  }

  // A number token; its integer value when it is one.
  std::optional<std::int64_t> number() {
    const std::size_t from = pos_;
    bool integral = true;
    while (pos_ < t_.size() && (std::isdigit(static_cast<unsigned char>(t_[pos_])) != 0 ||
                                std::strchr("+-.eE", t_[pos_]) != nullptr)) {
      integral = integral && std::strchr(".eE", t_[pos_]) == nullptr;
      ++pos_;
    }
    if (pos_ == from) fail("expected a value");
    if (!integral) return std::nullopt;
    errno = 0;
    const std::string token = t_.substr(from, pos_ - from);
    char* endp = nullptr;
    const long long v = std::strtoll(token.c_str(), &endp, 10);
    if (errno != 0 || endp == token.c_str() || *endp != '\0') fail("bad integer " + token);
    return v;
  }

  Prop value(const std::string& owner) {
    Prop p;
    const char c = t_[pos_];
    if (c == '"') {
      const std::size_t close = t_.find('"', pos_ + 1);
      if (close == std::string::npos) fail("a string has no closing quote");
      p.type = 'S';
      p.text = t_.substr(pos_ + 1, close - pos_ - 1);
      line_ += std::count(p.text.begin(), p.text.end(), '\n');
      pos_ = close + 1;
    } else if (c == '*') {
      ++pos_;
      (void)number();
      skip();
      if (pos_ >= t_.size() || t_[pos_] != '{') fail("an array without '{'");
      ++pos_;
      skip();
      if (name() != "a") fail("an array without 'a:'");
      p.type = 'l';
      for (skip(); pos_ < t_.size() && t_[pos_] != '}'; skip()) {
        if (t_[pos_] == ',') {
          ++pos_;
          continue;
        }
        const auto v = number();
        if (owner == "KeyTime") {
          if (!v) fail("a KeyTime that is not an integer");
          p.integers.push_back(*v);
        }
      }
      if (pos_ >= t_.size()) fail("an array without '}'");
      ++pos_;
    } else if (std::isalpha(static_cast<unsigned char>(c)) != 0) {
      while (pos_ < t_.size() && nameChar(t_[pos_])) ++pos_;  // T, Y, W...
    } else {
      const auto v = number();
      p.type = v ? 'L' : 'D';
      p.integer = v.value_or(0);
    }
    return p;
  }

  std::string path_;
  std::string t_;
  std::size_t pos_ = 0;
  long line_ = 1;
};

const Node* child(const Node& n, const std::string& name) {
  for (const Node& c : n.children)
    if (c.name == name) return &c;
  return nullptr;
}

// A stack's name without its class: "Name\x00\x01AnimStack" (binary) or
// "AnimStack::Name" (ASCII).
std::string objectName(const std::string& full) {
  const std::size_t binary = full.find(std::string("\x00\x01", 2));
  if (binary != std::string::npos) return full.substr(0, binary);
  const std::size_t ascii = full.find("::");
  return ascii == std::string::npos ? full : full.substr(ascii + 2);
}

std::vector<FbxTake> takesOf(const std::vector<Node>& top) {
  const Node* objects = nullptr;
  const Node* connections = nullptr;
  for (const Node& n : top) {
    if (n.name == "Objects") objects = &n;
    if (n.name == "Connections") connections = &n;
  }
  std::vector<FbxTake> takes;
  if (objects == nullptr) return takes;
  std::map<std::int64_t, std::size_t> stackIndex;
  std::map<std::int64_t, std::int64_t> curveFirstKey;
  for (const Node& o : objects->children) {
    if (o.name == "AnimationStack" && o.props.size() >= 2) {
      FbxTake take;
      take.name = objectName(o.props[1].text);
      if (const Node* props = child(o, "Properties70"))
        for (const Node& p : props->children)
          if (p.name == "P" && p.props.size() >= 5) {
            if (p.props[0].text == "LocalStart") take.localStart = p.props[4].integer;
            if (p.props[0].text == "LocalStop") take.localStop = p.props[4].integer;
          }
      stackIndex[o.props[0].integer] = takes.size();
      takes.push_back(std::move(take));
    } else if (o.name == "AnimationCurve" && !o.props.empty()) {
      const Node* keys = child(o, "KeyTime");
      if (keys == nullptr || keys->props.empty() || keys->props[0].integers.empty()) continue;
      const auto& k = keys->props[0].integers;
      curveFirstKey[o.props[0].integer] = *std::min_element(k.begin(), k.end());
    }
  }
  if (connections == nullptr) return takes;
  // Curve -> curve node -> layer -> stack.
  std::multimap<std::int64_t, std::int64_t> parents;
  for (const Node& c : connections->children)
    if (c.name == "C" && c.props.size() >= 3)
      parents.emplace(c.props[1].integer, c.props[2].integer);
  for (const auto& [curve, first] : curveFirstKey) {
    std::set<std::int64_t> level{curve};
    for (int up = 0; up < 3; ++up) {
      std::set<std::int64_t> next;
      for (const std::int64_t id : level) {
        const auto [from, to] = parents.equal_range(id);
        for (auto it = from; it != to; ++it) next.insert(it->second);
      }
      level = std::move(next);
    }
    for (const std::int64_t id : level) {
      const auto it = stackIndex.find(id);
      if (it == stackIndex.end()) continue;
      auto& key = takes[it->second].firstKey;
      key = key ? std::min(*key, first) : first;
    }
  }
  return takes;
}

}  // namespace

std::vector<FbxTake> readFbxTakes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  static constexpr char kMagic[] = "Kaydara FBX Binary  ";
  if (bytes.size() >= 27 && std::memcmp(bytes.data(), kMagic, sizeof kMagic - 1) == 0)
    return takesOf(BinaryReader(path, std::move(bytes)).read());
  return takesOf(AsciiReader(path, std::string(bytes.begin(), bytes.end())).read());
}

double assimpKeyShift(const FbxTake& take) {
  if (take.localStart != 0 || take.localStop != 0)
    return static_cast<double>(take.localStart) / kFbxTicksPerSecond;
  return take.firstKey ? static_cast<double>(*take.firstKey) / kFbxTicksPerSecond : 0.0;
}

}  // namespace crumple::io::detail
