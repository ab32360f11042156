// make_sound_db OUT_DIR: writes the generated default sound database (thesis
// 4.3.3; docs/SOUND.md "The default database") into OUT_DIR. The shipped
// assets/sound/default is its output: scripts/make-sound-db.sh regenerates it.
// Exit status (docs/ARCHITECTURE.md "The command line"): 0 written, 2 bad usage or an
// OUT_DIR that is not empty (without --force), 1 a failure while writing.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include "crumple/sound/database_generator.hpp"

namespace fs = std::filesystem;

namespace {

constexpr const char* kUsage =
    "usage: make_sound_db [--force] OUT_DIR\n"
    "\n"
    "Writes the default sound database (docs/SOUND.md \"The default database\") into\n"
    "OUT_DIR: index.toml, crumpling/*.wav and friction/*.txt, 82 cells. The output is\n"
    "the same, byte for byte, on every run.\n"
    "\n"
    "  --force     write into an OUT_DIR that is not empty: its index.toml, crumpling/\n"
    "              and friction/ are replaced, other files are left alone\n"
    "  -h, --help  this text\n"
    "\n"
    "Exit status: 0 written, 1 a failure while writing, 2 bad usage or a non-empty OUT_DIR.\n";

int usageError(const std::string& problem) {
  std::fprintf(stderr, "make_sound_db: %s\nusage: make_sound_db [--force] OUT_DIR (--help: more)\n",
               problem.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  bool force = false;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (arg == "--force") {
      force = true;
    } else if (arg.size() > 1 && arg.front() == '-') {
      return usageError("unknown option '" + std::string(arg) + "'");
    } else if (out.empty()) {
      out = arg;
    } else {
      return usageError("one OUT_DIR only (got '" + out + "' and '" + std::string(arg) + "')");
    }
  }
  if (out.empty()) return usageError("missing OUT_DIR");
  const fs::path dir(out);
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) {
      std::fprintf(stderr, "make_sound_db: %s: exists and is not a folder\n", out.c_str());
      return 2;
    }
    if (!fs::is_empty(dir, ec)) {
      if (!force) {
        std::fprintf(stderr,
                     "make_sound_db: %s: not empty; --force replaces its index.toml, crumpling/ "
                     "and friction/\n",
                     out.c_str());
        return 2;
      }
      try {
        fs::remove(dir / "index.toml");
        fs::remove_all(dir / "crumpling");
        fs::remove_all(dir / "friction");
      } catch (const std::exception& e) {
        std::fprintf(stderr, "make_sound_db: %s\n", e.what());
        return 1;
      }
    }
  }
  try {
    crumple::sound::generateDatabase(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_sound_db: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "make_sound_db: wrote the default sound database to %s\n", out.c_str());
  return 0;
}
