#pragma once
// Private helper: typed, validated access to one toml++ table, with errors in
// the house style "FILE:LINE: 'table.key': problem" (crumple::InputError).
#include <toml++/toml.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "crumple/core/types.hpp"

namespace crumple::io::detail {

// "3.5", "1e-06": shortest round-trippable-enough form for messages.
std::string formatNumber(double v);

// "a string", "an integer", ...: a node's type for messages.
const char* typeName(const toml::node& n);

// Parse TOML text; a syntax error becomes InputError("FILE:LINE: ...").
toml::table parseToml(std::string_view text, const std::string& sourceName);

// Read a whole file into a string; InputError("FILE: no such file") if absent.
std::string readTextFile(const std::string& path);

class TableReader {
 public:
  // path: the key path of this table ("scene", "handles[0]", "" for the root).
  TableReader(const toml::table& table, std::string path, std::string file);

  // Throws for the first key (in file order) that is not in `allowed`.
  void allowOnly(std::initializer_list<std::string_view> allowed) const;
  void allowOnly(std::span<const std::string_view> allowed) const;

  const toml::table& table() const { return table_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  // Line of the table header (or of its first key), 0 if unknown.
  long line() const;
  // "table.key" (or "key" for the root table).
  std::string keyPath(std::string_view key) const;

  const toml::node* find(std::string_view key) const;
  bool has(std::string_view key) const { return find(key) != nullptr; }
  // Line of `key`'s value, else of the table.
  long lineOf(std::string_view key) const;

  // Error at the key's line (or the table's line when the key is absent).
  [[noreturn]] void fail(std::string_view key, const std::string& problem) const;
  // Missing required key: error at the table's line.
  [[noreturn]] void missing(std::string_view key) const;

  // Typed getters: nullopt when absent; InputError on a wrong type or a
  // non-finite number. Integers are accepted where numbers are expected.
  std::optional<double> number(std::string_view key) const;
  std::optional<std::int64_t> integer(std::string_view key) const;
  std::optional<bool> boolean(std::string_view key) const;
  std::optional<std::string> string(std::string_view key) const;
  std::optional<Vec2> vec2(std::string_view key) const;
  std::optional<Vec3> vec3(std::string_view key) const;
  // An array of exactly two integers.
  std::optional<std::array<std::int64_t, 2>> intPair(std::string_view key) const;

  // A sub-table, or nullopt. InputError if the key holds something else.
  const toml::table* subTable(std::string_view key) const;
  // An array of tables ([[key]]), or nullptr. InputError if something else.
  const toml::array* tableArray(std::string_view key) const;

  // Value checks on a key that is present (call after reading it).
  double requirePositive(std::string_view key, double value) const;
  double requireNonNegative(std::string_view key, double value) const;
  // Every component in [lo, hi].
  Vec3 requireColor(std::string_view key, const Vec3& value, double hi) const;
  // Non-zero length; returns the unit vector.
  Vec3 requireDirection(std::string_view key, const Vec3& value) const;

 private:
  template <int N>
  std::optional<Eigen::Matrix<double, N, 1>> vector(std::string_view key) const;

  const toml::table& table_;
  std::string path_;
  std::string file_;
};

}  // namespace crumple::io::detail
