#pragma once
// Shared by the fuzz targets (docs/FUZZING.md): the readers under test take a
// path, so each input is written to one scratch file per process and suffix,
// overwritten by every input and removed at exit.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

namespace crumple::fuzz {

class ScratchFile {
 public:
  explicit ScratchFile(const std::string& suffix)
      : path_((std::filesystem::temp_directory_path() /
               ("crumple-fuzz-" + std::to_string(::getpid()) + suffix))
                  .string()) {}
  ~ScratchFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  // Replaces the file's content with the input; returns its path.
  const std::string& write(const std::uint8_t* data, std::size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) throw std::runtime_error("fuzz: cannot write " + path_);
    return path_;
  }

 private:
  std::string path_;
};

// One scratch file per suffix for the whole process (static, so removed at exit).
inline const std::string& writeScratch(const std::string& suffix, const std::uint8_t* data,
                                       std::size_t size) {
  static std::map<std::string, ScratchFile> files;
  auto it = files.find(suffix);
  if (it == files.end()) it = files.try_emplace(suffix, suffix).first;
  return it->second.write(data, size);
}

}  // namespace crumple::fuzz
