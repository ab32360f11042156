#include "toml_reader.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "crumple/core/error.hpp"

namespace crumple::io::detail {

const char* typeName(const toml::node& n) {
  static constexpr std::pair<toml::node_type, const char*> kNames[] = {
      {toml::node_type::table, "a table"},
      {toml::node_type::array, "an array"},
      {toml::node_type::string, "a string"},
      {toml::node_type::integer, "an integer"},
      {toml::node_type::floating_point, "a float"},
      {toml::node_type::boolean, "a boolean"},
      {toml::node_type::date, "a date"},
      {toml::node_type::time, "a time"},
      {toml::node_type::date_time, "a date-time"}};
  for (const auto& [type, name] : kNames)
    if (n.type() == type) return name;
  return "nothing";
}

namespace {

long nodeLine(const toml::node& n) { return static_cast<long>(n.source().begin.line); }

}  // namespace

std::string formatNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

toml::table parseToml(std::string_view text, const std::string& sourceName) {
  try {
    return toml::parse(text, sourceName);
  } catch (const toml::parse_error& e) {
    throw InputError(sourceName + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
}

std::string readTextFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (std::filesystem::exists(path, ec)) throw InputError(path, "not a regular file");
    throw InputError(path, "no such file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return ss.str();
}

TableReader::TableReader(const toml::table& table, std::string path, std::string file)
    : table_(table), path_(std::move(path)), file_(std::move(file)) {}

void TableReader::allowOnly(std::initializer_list<std::string_view> allowed) const {
  allowOnly(std::span<const std::string_view>(allowed.begin(), allowed.size()));
}

void TableReader::allowOnly(std::span<const std::string_view> allowed) const {
  // Report the first offending key in file order (toml++ tables are sorted by key).
  const toml::key* worst = nullptr;
  for (auto&& [k, v] : table_) {
    bool ok = false;
    for (std::string_view a : allowed) ok = ok || (k.str() == a);
    if (ok) continue;
    if (!worst || k.source().begin.line < worst->source().begin.line) worst = &k;
  }
  if (!worst) return;
  std::string list;
  for (std::string_view a : allowed) {
    if (!list.empty()) list += ", ";
    list += a;
  }
  const long line =
      worst->source().begin.line ? static_cast<long>(worst->source().begin.line) : this->line();
  throw InputError(
      file_, line, keyPath(worst->str()),
      "unknown key" + (list.empty() ? std::string() : " (expected one of: " + list + ")"));
}

long TableReader::line() const {
  long l = nodeLine(table_);
  if (l > 0) return l;
  long first = 0;
  for (auto&& [k, v] : table_) {
    const long kl = static_cast<long>(k.source().begin.line);
    if (kl > 0 && (first == 0 || kl < first)) first = kl;
  }
  return first;
}

std::string TableReader::keyPath(std::string_view key) const {
  if (path_.empty()) return std::string(key);
  return path_ + "." + std::string(key);
}

const toml::node* TableReader::find(std::string_view key) const { return table_.get(key); }

long TableReader::lineOf(std::string_view key) const {
  if (const toml::node* n = find(key)) {
    if (long l = nodeLine(*n); l > 0) return l;
  }
  return line();
}

void TableReader::fail(std::string_view key, const std::string& problem) const {
  throw InputError(file_, lineOf(key), keyPath(key), problem);
}

void TableReader::missing(std::string_view key) const {
  throw InputError(file_, line(), keyPath(key), "missing required key");
}

std::optional<double> TableReader::number(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  double v = 0.0;
  if (auto f = n->as_floating_point()) {
    v = f->get();
  } else if (auto i = n->as_integer()) {
    v = static_cast<double>(i->get());
  } else {
    fail(key, std::string("expected a number, got ") + typeName(*n));
  }
  if (!std::isfinite(v)) fail(key, "must be a finite number (got " + formatNumber(v) + ")");
  return v;
}

std::optional<std::int64_t> TableReader::integer(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  if (auto i = n->as_integer()) return i->get();
  fail(key, std::string("expected an integer, got ") + typeName(*n));
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  if (auto b = n->as_boolean()) return b->get();
  fail(key, std::string("expected true or false, got ") + typeName(*n));
}

std::optional<std::string> TableReader::string(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  if (auto s = n->as_string()) return s->get();
  fail(key, std::string("expected a string, got ") + typeName(*n));
}

template <int N>
std::optional<Eigen::Matrix<double, N, 1>> TableReader::vector(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  const std::string expected = "expected an array of " + std::to_string(N) + " numbers";
  if (!a) fail(key, expected + ", got " + typeName(*n));
  if (a->size() != static_cast<std::size_t>(N)) {
    fail(key, expected + ", got " + std::to_string(a->size()) + " elements");
  }
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) {
    const toml::node& e = *a->get(static_cast<std::size_t>(i));
    if (auto f = e.as_floating_point()) {
      v[i] = f->get();
    } else if (auto k = e.as_integer()) {
      v[i] = static_cast<double>(k->get());
    } else {
      fail(key, expected + ", element " + std::to_string(i) + " is " + typeName(e));
    }
    if (!std::isfinite(v[i])) {
      fail(key, "element " + std::to_string(i) + " must be a finite number (got " +
                    formatNumber(v[i]) + ")");
    }
  }
  return v;
}

std::optional<Vec2> TableReader::vec2(std::string_view key) const { return vector<2>(key); }
std::optional<Vec3> TableReader::vec3(std::string_view key) const { return vector<3>(key); }

std::optional<std::array<std::int64_t, 2>> TableReader::intPair(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  if (!a || a->size() != 2 || !a->get(0)->is_integer() || !a->get(1)->is_integer()) {
    fail(key, "expected an array of two integers, e.g. [1, 48]");
  }
  return std::array<std::int64_t, 2>{a->get(0)->as_integer()->get(),
                                     a->get(1)->as_integer()->get()};
}

const toml::table* TableReader::subTable(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return nullptr;
  if (const toml::table* t = n->as_table()) return t;
  fail(key, std::string("expected a table, got ") + typeName(*n));
}

const toml::array* TableReader::tableArray(std::string_view key) const {
  const toml::node* n = find(key);
  if (!n) return nullptr;
  const toml::array* a = n->as_array();
  if (!a) {
    fail(key, std::string("expected an array of tables ([[") + std::string(key) + "]]), got " +
                  typeName(*n));
  }
  for (const toml::node& e : *a) {
    if (!e.is_table()) {
      fail(key, std::string("expected an array of tables ([[") + std::string(key) + "]]), found " +
                    typeName(e));
    }
  }
  return a;
}

double TableReader::requirePositive(std::string_view key, double value) const {
  if (!(value > 0.0)) fail(key, "must be > 0 (got " + formatNumber(value) + ")");
  return value;
}

double TableReader::requireNonNegative(std::string_view key, double value) const {
  if (!(value >= 0.0)) fail(key, "must be >= 0 (got " + formatNumber(value) + ")");
  return value;
}

Vec3 TableReader::requireColor(std::string_view key, const Vec3& value, double hi) const {
  for (int i = 0; i < 3; ++i) {
    if (!(value[i] >= 0.0 && value[i] <= hi)) {
      fail(key, "component " + std::to_string(i) + " must be in [0, " + formatNumber(hi) +
                    "] (got " + formatNumber(value[i]) + ")");
    }
  }
  return value;
}

Vec3 TableReader::requireDirection(std::string_view key, const Vec3& value) const {
  const double n = value.norm();
  if (!(n > 1e-12)) fail(key, "must be a non-zero vector");
  return value / n;
}

template std::optional<Eigen::Matrix<double, 2, 1>> TableReader::vector<2>(std::string_view) const;
template std::optional<Eigen::Matrix<double, 3, 1>> TableReader::vector<3>(std::string_view) const;

}  // namespace crumple::io::detail
