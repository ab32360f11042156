// libFuzzer target: what the tools built on the cache do with it. The cache
// target (fuzz_cache.cpp) reads and decodes; this one hands what reads to
// the code that indexes with it: `crumple inspect`'s measures of every frame
// (pipeline::inspectJson), the frame views the renderers draw
// (pipeline::FrameViewBuilder, the scene re-parsed from the header as
// `crumple render` does) and one export (the format picked by the input's
// last byte) into a scratch folder. Each input runs as given and with the
// CRC of every chunk recomputed (fuzz_pcache.hpp), so that hostile indices
// and reals inside CRC-valid frames reach the tools. Anything but
// crumple::InputError or crumple::CorruptDataError is a bug.
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/export.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shot.hpp"
#include "fuzz_input.hpp"
#include "fuzz_pcache.hpp"

namespace {

namespace fs = std::filesystem;
using crumple::CorruptDataError;
using crumple::InputError;

// One scratch folder per process for the exports, removed at exit.
const std::string& exportFolder() {
  struct Folder {
    fs::path path =
        fs::temp_directory_path() / ("crumple-fuzz-export-" + std::to_string(::getpid()));
    ~Folder() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Folder folder;
  static const std::string path = folder.path.string();
  return path;
}

void inspect(const crumple::cache::CacheReader& reader) {
  try {
    (void)crumple::pipeline::inspectJson(reader);
  } catch (const CorruptDataError&) {
  } catch (const InputError&) {
  }
}

void frameViews(const crumple::cache::CacheReader& reader) {
  const auto& header = reader.header();
  try {
    const crumple::io::SceneSpec scene = crumple::io::parseScene(
        header.sceneText, "fuzz.toml", fs::temp_directory_path().string(), /*checkFiles=*/false);
    const crumple::pipeline::FrameViewBuilder builder(scene, header.extensions);
    for (std::size_t i = 0; i < reader.frameCount(); ++i) {
      try {
        (void)builder.build(reader.readFrame(i));
      } catch (const CorruptDataError&) {
      }
    }
  } catch (const CorruptDataError&) {
  } catch (const InputError&) {
  }
}

void exportOne(const std::string& path, std::uint8_t pick) {
  crumple::pipeline::ExportOptions options;
  constexpr crumple::pipeline::ExportFormat kFormats[] = {
      crumple::pipeline::ExportFormat::Obj, crumple::pipeline::ExportFormat::Ply,
      crumple::pipeline::ExportFormat::Gltf, crumple::pipeline::ExportFormat::Usda};
  options.format = kFormats[pick % 4];
  options.outDir = exportFolder();
  options.log = nullptr;
  try {
    (void)crumple::pipeline::exportCache(path, options);
  } catch (const CorruptDataError&) {
  } catch (const InputError&) {
  }
}

void useCache(const std::uint8_t* data, std::size_t size) {
  const std::string& path = crumple::fuzz::writeScratch(".pcache", data, size);
  try {
    const crumple::cache::CacheReader reader(path);
    inspect(reader);
    frameViews(reader);
  } catch (const InputError&) {
    return;  // a missing or damaged header: the intended behaviour
  }
  exportOne(path, size > 0 ? data[size - 1] : 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  crumple::fuzz::asGivenAndWithValidCrcs(data, size, useCache);
  return 0;
}
