#include "crumple/core/debug.hpp"

#include <utility>

#include "crumple/core/error.hpp"

namespace crumple {

namespace {
DebugOptions& current() {
  static DebugOptions options;
  return options;
}
}  // namespace

const DebugOptions& debugOptions() { return current(); }

void setDebugOptions(DebugOptions options) { current() = std::move(options); }

DebugOptions parseDebugOptions(std::string_view text) {
  DebugOptions out;
  const auto bad = [](std::string_view why) { return InputError("--debug", std::string(why)); };
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    const std::string_view item = text.substr(0, comma);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    const std::size_t eq = item.find('=');
    const std::string_view name = item.substr(0, eq);
    const std::string_view value =
        eq == std::string_view::npos ? std::string_view{} : item.substr(eq + 1);
    if (name == "newton" && eq == std::string_view::npos) {
      out.newton = true;
    } else if (name == "tear" && eq == std::string_view::npos) {
      out.tear = true;
    } else if (name == "invariants" && eq == std::string_view::npos) {
      out.invariants = true;
    } else if (name == "geometry") {
      if (value.empty() && eq == std::string_view::npos)
        out.geometry = 1;
      else if (value.size() == 1 && value[0] >= '1' && value[0] <= '3')
        out.geometry = value[0] - '0';
      else
        throw bad("geometry takes a level 1, 2 or 3, got '" + std::string(value) + "'");
    } else if (name == "dump") {
      if (value.empty()) throw bad("dump needs a file: dump=FILE");
      out.dump = std::string(value);
    } else {
      throw bad("unknown switch '" + std::string(item) +
                "' (known: newton, geometry[=1-3], tear, invariants, dump=FILE)");
    }
  }
  return out;
}

}  // namespace crumple
