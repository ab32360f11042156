// The forked import probe (src/io/src/import_probe.hpp; docs/FUZZING.md):
// what a child that crashes, asserts, hangs or finishes turns into.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "crumple/core/error.hpp"
#include "import_probe.hpp"

namespace {

using crumple::InputError;
using crumple::io::detail::probeInChild;
using namespace std::chrono_literals;

std::string probeMessage(const std::function<std::string()>& import,
                         std::chrono::milliseconds deadline) {
  try {
    probeInChild("file.dae", import, deadline, 0);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ImportProbe, AChildThatFinishesLetsTheImportGoOn) {
  EXPECT_EQ(probeInChild(
                "file.dae", [] { return std::string(); }, 10s, 0),
            std::string());
  // The child's work does not reach this process.
  int touched = 0;
  EXPECT_EQ(probeInChild(
                "file.dae",
                [&touched] {
                  touched = 1;
                  return std::string();
                },
                10s, 0),
            std::string());
  EXPECT_EQ(touched, 0);
}

TEST(ImportProbe, TheImportersReasonComesBack) {
  EXPECT_EQ(probeInChild(
                "file.dae", [] { return std::string("no suitable reader"); }, 10s, 0),
            "no suitable reader");
}

#if !defined(__SANITIZE_ADDRESS__) && !defined(__has_feature)
#define CRUMPLE_PROBE_LIMITS_MEMORY 1
#elif defined(__has_feature)
#if !__has_feature(address_sanitizer)
#define CRUMPLE_PROBE_LIMITS_MEMORY 1
#endif
#endif

// Without a sanitizer the child runs under the memory limit: an allocation
// beyond it fails there (the importer reports it) instead of growing the
// machine's memory use.
TEST(ImportProbe, TheChildRunsUnderTheMemoryLimit) {
#ifdef CRUMPLE_PROBE_LIMITS_MEMORY
  const std::optional<std::string> reason = probeInChild(
      "file.dae",
      [] {
        try {
          std::vector<char> big(std::size_t(8) << 30);
          big[0] = 1;
          return std::string("allocated");
        } catch (const std::bad_alloc&) {
          return std::string("out of memory");
        }
      },
      10s, std::size_t(512) << 20);
  EXPECT_EQ(reason, "out of memory");
#else
  GTEST_SKIP() << "a sanitizer's shadow memory rules out an address-space limit";
#endif
}

TEST(ImportProbe, ASignalBecomesAnInputErrorNamingFileSignalAndAssertion) {
  const std::string aborted = probeMessage(
      []() -> std::string {
        std::fputs("some noise\nai_assert failure in Loader.cpp(7): pos < size\nmore\n", stderr);
        std::abort();
      },
      10s);
  EXPECT_NE(aborted.find("file.dae: the importer (assimp) crashed"), std::string::npos) << aborted;
  EXPECT_NE(aborted.find("signal " + std::to_string(SIGABRT)), std::string::npos) << aborted;
  EXPECT_NE(aborted.find("assimp said: ai_assert failure in Loader.cpp(7): pos < size"),
            std::string::npos)
      << aborted;
  const std::string segv = probeMessage(
      [] {
        std::raise(SIGSEGV);
        return std::string();
      },
      10s);
  EXPECT_NE(segv.find("signal " + std::to_string(SIGSEGV)), std::string::npos) << segv;
}

TEST(ImportProbe, AnExitWithAnotherStatusIsAFailure) {
  const std::string failed = probeMessage([]() -> std::string { std::_Exit(1); }, 10s);
  EXPECT_NE(failed.find("failed on this file (exit status 1)"), std::string::npos) << failed;
}

TEST(ImportProbe, AHangIsKilledAtTheDeadline) {
  const auto start = std::chrono::steady_clock::now();
  const std::string hung = probeMessage(
      [] {
        std::this_thread::sleep_for(60s);
        return std::string();
      },
      300ms);
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_NE(hung.find("did not finish within 0.3 s"), std::string::npos) << hung;
  EXPECT_LT(took, 30s);
}

}  // namespace
