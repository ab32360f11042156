#include "crumple/render/aov.hpp"

#include <array>
#include <stdexcept>

namespace crumple::render {

namespace {

constexpr std::array<std::string_view, kAovCount> kNames = {
    "depth", "normal", "albedo", "position", "region", "handle-id", "object-id"};

}  // namespace

std::string_view aovName(Aov aov) { return kNames[static_cast<std::size_t>(aov)]; }

std::optional<Aov> parseAov(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return static_cast<Aov>(i);
  return std::nullopt;
}

std::vector<Aov> parseAovList(std::string_view list) {
  std::array<bool, kAovCount> wanted{};
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t comma = list.find(',', begin);
    const std::size_t end = comma == std::string_view::npos ? list.size() : comma;
    const std::string_view item = list.substr(begin, end - begin);
    const std::optional<Aov> aov = parseAov(item);
    if (!aov) {
      std::string known;
      for (const std::string_view n : kNames) known += (known.empty() ? "" : ", ") + std::string(n);
      throw std::invalid_argument("'" + std::string(item) + "' is not an AOV (" + known + ")");
    }
    if (wanted[static_cast<std::size_t>(*aov)])
      throw std::invalid_argument("AOV '" + std::string(item) + "' is listed twice");
    wanted[static_cast<std::size_t>(*aov)] = true;
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
  std::vector<Aov> out;
  for (std::size_t i = 0; i < wanted.size(); ++i)
    if (wanted[i]) out.push_back(static_cast<Aov>(i));
  return out;
}

std::vector<std::string> aovChannelNames(Aov aov) {
  switch (aov) {
    case Aov::Depth:
      return {"Z"};
    case Aov::Normal:
      return {"N.X", "N.Y", "N.Z"};
    case Aov::Albedo:
      return {"albedo.R", "albedo.G", "albedo.B"};
    case Aov::Position:
      return {"P.X", "P.Y", "P.Z"};
    case Aov::Region:
      return {"region.R", "region.G", "region.B"};
    case Aov::HandleId:
      return {"IndexHandle.X"};
    case Aov::ObjectId:
      return {"IndexOB.X"};
  }
  return {};
}

}  // namespace crumple::render
