#pragma once
// The benchmarks read single numbers out of the JSON files crumple and the
// Blender script write (summary.json, *.timing.json): no JSON library needed.
#include <cctype>
#include <cstdlib>
#include <string>

namespace crumple::bench {

// The number after the first `"key":` (whitespace allowed) in `text`, or
// `fallback` when the key is absent or holds no number.
inline double jsonNumber(const std::string& text, const std::string& key, double fallback) {
  const std::string quoted = "\"" + key + "\":";
  const std::size_t at = text.find(quoted);
  if (at == std::string::npos) return fallback;
  std::size_t pos = at + quoted.size();
  while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  const char* begin = text.c_str() + pos;
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  return end == begin ? fallback : v;
}

}  // namespace crumple::bench
