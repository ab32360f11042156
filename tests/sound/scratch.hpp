#pragma once
// A scratch folder for one test, removed with it (tests/sound).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace crumple::testing {

struct SoundScratch {
  std::filesystem::path dir;
  SoundScratch() {
    dir = std::filesystem::temp_directory_path() /
          ("crumple-test-sound-" + std::to_string(::getpid()) + "-" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~SoundScratch() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  SoundScratch(const SoundScratch&) = delete;
  SoundScratch& operator=(const SoundScratch&) = delete;
};

}  // namespace crumple::testing
