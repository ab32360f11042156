#include "shot_inputs.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>

#include "crumple/core/error.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// Hashes a file's bytes, reading it in blocks; keeps its text when `text`
// is given (a .gltf, whose URIs are read next).
ShotInput hashFile(const std::string& what, const std::string& path, std::string* text = nullptr) {
  const std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) throw InputError(path, std::string("cannot read ") + what + ": " + std::strerror(errno));
  ShotInput input{what, path, 0, kFnv1aStart};
  char block[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(block, 1, sizeof block, f.get())) > 0) {
    input.hash = fnv1a64(block, n, input.hash);
    input.size += n;
    if (text != nullptr) text->append(block, n);
  }
  if (std::ferror(f.get()) != 0) throw InputError(path, "cannot read " + what);
  return input;
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// A glTF URI as a file name: JSON's "\/" unescaped, %XX decoded.
std::string uriPath(std::string_view uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '\\' && i + 1 < uri.size()) {
      out += uri[++i];
    } else if (uri[i] == '%' && i + 2 < uri.size() && hexDigit(uri[i + 1]) >= 0 &&
               hexDigit(uri[i + 2]) >= 0) {
      out += static_cast<char>(hexDigit(uri[i + 1]) * 16 + hexDigit(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// The values of every "uri" key of a glTF file's JSON, but data: URIs.
std::vector<std::string> externalUris(std::string_view json) {
  std::vector<std::string> uris;
  constexpr std::string_view kKey = "\"uri\"";
  for (std::size_t at = json.find(kKey); at != std::string_view::npos;
       at = json.find(kKey, at + 1)) {
    std::size_t i = at + kKey.size();
    while (i < json.size() && std::isspace(static_cast<unsigned char>(json[i])) != 0) ++i;
    if (i >= json.size() || json[i] != ':') continue;
    ++i;
    while (i < json.size() && std::isspace(static_cast<unsigned char>(json[i])) != 0) ++i;
    if (i >= json.size() || json[i] != '"') continue;
    std::size_t end = ++i;
    while (end < json.size() && json[end] != '"') end += json[end] == '\\' ? 2 : 1;
    if (end > json.size()) break;
    const std::string_view uri = json.substr(i, end - i);
    if (uri.rfind("data:", 0) != 0 && !uri.empty()) uris.push_back(uriPath(uri));
  }
  return uris;
}

bool isGltf(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".gltf";
}

}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::vector<ShotInput> shotInputs(const io::SceneSpec& scene) {
  std::vector<ShotInput> inputs;
  if (!scene.animationFile.empty()) {
    std::string json;
    const bool gltf = isGltf(scene.animationFile);
    inputs.push_back(hashFile("the animation file", scene.animationFile, gltf ? &json : nullptr));
    const fs::path base = fs::path(scene.animationFile).parent_path();
    for (const std::string& uri : externalUris(json))
      inputs.push_back(
          hashFile("the file the animation file names", (base / uri).lexically_normal().string()));
  }
  if (!scene.paper.file.empty()) inputs.push_back(hashFile("the paper preset", scene.paper.file));
  if (!scene.look.texture.empty())
    inputs.push_back(hashFile("the paper texture", scene.look.texture));
  return inputs;
}

}  // namespace crumple::pipeline
