// Checkpoint and resume: a run killed with SIGKILL at a
// random frame and resumed from its last checkpoint writes a cache
// byte-identical to an uninterrupted run's; checkpoints do not change the
// cache; a checkpoint of another shot, a damaged one or none is refused.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include "crumple/cache/pcache.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)
namespace fs = std::filesystem;

namespace {

const std::string kSample = "samples/drape";

// Starts `crumple simulate` on `sample` (frames 0 to `last`) into `out`
// with checkpoints, in the background; returns its pid.
pid_t startSimulation(const std::string& sample, int last, const fs::path& out, int every) {
  const std::string bin = CRUMPLE_BIN;
  const std::string scene = sourcePath(sample);
  const std::string frames = "0-" + std::to_string(last);
  const std::string outDir = out.string();
  const std::string everyText = std::to_string(every);
  std::fflush(nullptr);  // the child must not repeat what the parent buffered
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string log = (out.parent_path() / (out.filename().string() + ".log")).string();
    std::FILE* sink = std::freopen(log.c_str(), "w", stdout);
    (void)sink;
    ::dup2(::fileno(stdout), 2);
    ::execl(bin.c_str(), bin.c_str(), "simulate", scene.c_str(), "--out", outDir.c_str(),
            "--frames", frames.c_str(), "--checkpoint-every", everyText.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

// Complete frames in a cache being written (0 while it has none).
std::size_t framesIn(const fs::path& cache) {
  try {
    return cache::CacheReader(cache.string()).frameCount();
  } catch (const std::exception&) {
    return 0;
  }
}

// One sample (frames 0 to `last`): run whole, with checkpoints every 6
// frames and without, then killed `kills` times, with from `earliest`
// frames to all but 4 cached (drawn at random), and resumed.
void killAndResume(const std::string& sample, int last, int kills, unsigned seed,
                   std::size_t earliest = 8) {
  const TempDir dir;
  const std::string frames = " --frames 0-" + std::to_string(last);
  const auto plain =
      runCrumple("simulate " + sourcePath(sample) + " --out " + (dir / "plain").string() + frames);
  ASSERT_EQ(plain.status, 0) << plain.output;
  const auto whole = runCrumple("simulate " + sourcePath(sample) + " --out " +
                                (dir / "whole").string() + frames + " --checkpoint-every 6");
  ASSERT_EQ(whole.status, 0) << whole.output;
  const std::string reference = readFile(dir / "plain" / "cache.pcache");
  ASSERT_FALSE(reference.empty());
  EXPECT_EQ(readFile(dir / "whole" / "cache.pcache"), reference) << "checkpoints changed it";
  const std::size_t total = framesIn(dir / "plain" / "cache.pcache");
  ASSERT_GT(total, 16u);
  // Seeded draws: the same kill frames every run.
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> when(earliest, total - 4);
  for (int trial = 0; trial < kills; ++trial) {
    const fs::path out = dir / ("killed" + std::to_string(trial));
    const std::size_t killAt = when(rng);
    const pid_t pid = startSimulation(sample, last, out, 6);
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
    while (framesIn(out / "cache.pcache") < killAt && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_EQ(::kill(pid, SIGKILL), 0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed";
    const std::size_t cachedWhenKilled = framesIn(out / "cache.pcache");
    const auto resumed = runCrumple("simulate " + sourcePath(sample) + " --out " + out.string() +
                                    frames + " --checkpoint-every 6 --resume");
    ASSERT_EQ(resumed.status, 0) << resumed.output;
    const auto at = resumed.output.find("resuming after frame ");
    ASSERT_NE(at, std::string::npos) << resumed.output;
    std::printf("[ measure ] %s: killed with %zu of %zu frames cached; %s\n", sample.c_str(),
                cachedWhenKilled, total,
                resumed.output.substr(at, resumed.output.find(" (", at) - at).c_str());
    EXPECT_EQ(readFile(out / "cache.pcache"), reference) << sample << ", trial " << trial;
  }
}

}  // namespace

// The elastic model.
TEST(Checkpoint, AKilledRunResumesToTheSameBytes) { killAndResume(kSample, 72, 2, 8); }

// The crumpling model (S_G, S_P, singular vertices, rulings, junctions).
TEST(Checkpoint, AKilledCrumplingModelResumesToTheSameBytes) {
  killAndResume("samples/crumple", 108, 2, 11);
}

// A torn sheet (tears, lips, the tear textures): tear-straight tears at
// frame 15, so a kill after 20 frames resumes from a torn state (the
// checkpoint of frame 18 or later).
TEST(Checkpoint, AKilledTearResumesToTheSameBytes) {
  killAndResume("samples/tear-straight", 32, 1, 5, 20);
}

TEST(Checkpoint, ResumeRefusesWhatItCannotContinue) {
  const TempDir dir;
  const fs::path out = dir / "shot";
  // Nothing to resume from.
  auto r = runCrumple("simulate " + sourcePath(kSample) + " --out " + out.string() + " --resume");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("no checkpoint"), std::string::npos) << r.output;
  ASSERT_EQ(runCrumple("simulate " + sourcePath(kSample) + " --out " + out.string() +
                       " --frames 0-12 --checkpoint-every 4")
                .status,
            0);
  // Another frame range, another seed: another shot.
  r = runCrumple("simulate " + sourcePath(kSample) + " --out " + out.string() +
                 " --frames 0-20 --checkpoint-every 4 --resume");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("cannot resume"), std::string::npos) << r.output;
  r = runCrumple("simulate " + sourcePath(kSample) + " --out " + out.string() +
                 " --frames 0-12 --seed 9 --resume");
  EXPECT_EQ(r.status, 2);
  // A damaged checkpoint.
  {
    std::fstream f(out / "checkpoint.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.put('\x5a');
  }
  r = runCrumple("simulate " + sourcePath(kSample) + " --out " + out.string() +
                 " --frames 0-12 --resume");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("damaged"), std::string::npos) << r.output;
}

// Fingers that hold patches (their patch points, rebound on every rebuild
// of S_P and after each cut): tear-cylinder's patches variant tears at
// frame 44, so the kill falls before or after it.
TEST(Checkpoint, FingersHoldingPatchesResumeToTheSameBytes) {
  killAndResume("samples/tear-cylinder/patches.toml", 48, 1, 3);
}
