// One writer per output folder: a crumple writing into a folder holds its
// lock (DIR/.crumple.lock); a second writer there is refused with exit 2,
// naming the folder and the holder's pid; a lock file left behind blocks
// nobody; renders and exports of frame ranges share a folder (the farm's
// array tasks), a whole render or export does not.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <optional>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/pipeline/shot.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;
using pipeline::OutputLock;

namespace {

std::string pidText(long pid) { return "(pid " + std::to_string(pid) + ")"; }

// The message of the lock `dir` being refused, or "" when it was taken.
std::string refusal(const fs::path& dir, OutputLock::Mode mode = OutputLock::Mode::Exclusive) {
  try {
    const OutputLock lock(dir.string(), mode);
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

// A child process holding `dir`'s lock until release() (or the end of the
// test): another crumple, as far as the folder can tell.
class LockHolder {
 public:
  explicit LockHolder(const fs::path& dir) {
    int ready[2], go[2];
    if (::pipe(ready) != 0 || ::pipe(go) != 0) return;
    std::fflush(nullptr);  // the child must not repeat what the parent buffered
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(ready[0]);
      ::close(go[1]);
      char byte = 'n';
      try {
        const OutputLock lock(dir.string());
        byte = 'y';
        (void)!::write(ready[1], &byte, 1);
        (void)!::read(go[0], &byte, 1);  // until the parent closes its end
      } catch (...) {
        (void)!::write(ready[1], &byte, 1);
      }
      ::_exit(0);
    }
    ::close(ready[1]);
    ::close(go[0]);
    go_ = go[1];
    char byte = 'n';
    held_ = ::read(ready[0], &byte, 1) == 1 && byte == 'y';
    ::close(ready[0]);
  }
  ~LockHolder() { release(); }
  LockHolder(const LockHolder&) = delete;
  LockHolder& operator=(const LockHolder&) = delete;
  void release() {
    if (go_ >= 0) ::close(go_);
    go_ = -1;
    if (pid_ > 0) ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  pid_t pid() const { return pid_; }
  bool held() const { return held_; }

 private:
  pid_t pid_ = -1;
  int go_ = -1;
  bool held_ = false;
};

// A small shot with [sound] (so that `crumple sound` gets as far as the lock).
fs::path writeSoundScene(const TempDir& tmp) {
  writeSmallScene(tmp / "scene");
  writeFile(tmp / "scene/scene.toml", smallSceneToml() + "[sound]\n");
  return tmp / "scene";
}

}  // namespace

TEST(OutputLock, ASecondWriterIsRefusedNamingTheFolderAndTheHoldersPid) {
  const TempDir tmp;
  const fs::path dir = tmp / "shot";
  std::optional<OutputLock> first(std::in_place, dir.string());
  EXPECT_TRUE(first->held());
  EXPECT_TRUE(fs::exists(dir / pipeline::kOutputLockFile));
  const std::string message = refusal(dir);
  EXPECT_NE(message.find(dir.string() + " is being written by another crumple " +
                         pidText(::getpid()) + "; wait for it or choose another --out"),
            std::string::npos)
      << message;
  first.reset();  // closing the descriptor releases it
  EXPECT_EQ(refusal(dir), "");
}

TEST(OutputLock, AStaleLockFileBlocksNobody) {
  // A crumple killed while writing leaves its lock file (with its pid) but
  // no lock: the next run goes on.
  const TempDir tmp;
  writeSmallScene(tmp / "scene");
  fs::create_directories(tmp / "out");
  writeFile(tmp / "out" / pipeline::kOutputLockFile, "999999\n");
  EXPECT_EQ(refusal(tmp / "out"), "");
  const auto r =
      runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "out").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "out/cache.pcache"));
  // The one that held it empties it when it is done.
  EXPECT_EQ(readFile(tmp / "out" / pipeline::kOutputLockFile), "");
}

TEST(OutputLock, SharedHoldersShareAndExcludeAnExclusiveOne) {
  const TempDir tmp;
  const fs::path dir = tmp / "frames";
  {
    const OutputLock a(dir.string(), OutputLock::Mode::Shared);
    const OutputLock b(dir.string(), OutputLock::Mode::Shared);
    EXPECT_NE(refusal(dir).find("is being written by another crumple"), std::string::npos);
  }
  const OutputLock whole(dir.string());
  EXPECT_NE(refusal(dir, OutputLock::Mode::Shared).find("is being written by another crumple"),
            std::string::npos);
}

TEST(OutputLock, SimulateIntoAFolderAnotherCrumpleWritesExitsTwo) {
  const TempDir tmp;
  writeSmallScene(tmp / "scene");
  const fs::path out = tmp / "out";
  const std::string simulate =
      "simulate " + (tmp / "scene").string() + " --out " + out.string() + " --checkpoint-every 2";
  LockHolder other(out);
  ASSERT_TRUE(other.held());
  auto r = runCrumple(simulate);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(
      r.output.find(out.string() + " is being written by another crumple " + pidText(other.pid())),
      std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out / "cache.pcache")) << "nothing is written into a folder in use";
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  // Nor does a resume touch it.
  r = runCrumple(simulate + " --resume");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(pidText(other.pid())), std::string::npos) << r.output;
  other.release();
  r = runCrumple(simulate);
  EXPECT_EQ(r.status, 0) << r.output;
  // The library entry point holds the lock the same way.
  const OutputLock held(out.string());
  pipeline::ShotOptions options;
  options.outDir = out.string();
  options.render = false;
  options.log = nullptr;
  options.interactive = 0;
  const auto scene = io::loadScene((tmp / "scene/scene.toml").string());
  try {
    (void)pipeline::runShot(scene, options);
    FAIL() << "runShot wrote into a folder another writer holds";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(pidText(::getpid())), std::string::npos) << e.what();
  }
}

TEST(OutputLock, RunRenderSoundAndExportHoldTheFoldersTheyWriteInto) {
  const TempDir tmp;
  const fs::path scene = writeSoundScene(tmp);
  const fs::path shot = tmp / "shot";
  ASSERT_EQ(runCrumple("simulate " + scene.string() + " --out " + shot.string()).status, 0);
  const std::string cache = (shot / "cache.pcache").string();
  const std::string refused = "is being written by another crumple " + pidText(::getpid());
  const auto expectRefused = [&](const std::string& args, const fs::path& folder) {
    const auto r = runCrumple(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(folder.string() + " " + refused), std::string::npos) << args << "\n"
                                                                                 << r.output;
  };
  {
    // `run` writes into DIR and DIR/frames.
    const OutputLock frames((tmp / "run/frames").string());
    expectRefused("run " + scene.string() + " --out " + (tmp / "run").string(), tmp / "run/frames");
  }
  {
    // `sound`: the WAV's folder.
    const OutputLock folder(shot.string());
    expectRefused("sound " + cache, shot);
    expectRefused("sound " + cache + " --out " + (shot / "other.wav").string(), shot);
  }
  {
    // A whole render has its folder alone; a range cannot share it with it.
    const OutputLock frames((shot / "frames").string());
    expectRefused("render " + cache, shot / "frames");
    expectRefused("render " + cache + " --frames 1-2", shot / "frames");
  }
  {
    // Renders of frame ranges share it (a farm's array tasks), a whole one
    // cannot join them.
    const OutputLock chunk((shot / "frames").string(), OutputLock::Mode::Shared);
    const auto r = runCrumple("render " + cache + " --frames 1-3");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(shot / "frames/0003.png"));
    expectRefused("render " + cache, shot / "frames");
    expectRefused("render " + cache + " --out " + (shot / "frames").string(), shot / "frames");
  }
  {
    const OutputLock folder((shot / "export/obj").string());
    expectRefused("export " + cache + " --format obj", shot / "export/obj");
  }
  {
    const OutputLock chunk((shot / "export/ply").string(), OutputLock::Mode::Shared);
    EXPECT_EQ(runCrumple("export " + cache + " --format ply --frames 1-2").status, 0);
    expectRefused("export " + cache + " --format ply", shot / "export/ply");
  }
  // Released: every one of them writes.
  for (const std::string& args :
       {"run " + scene.string() + " --out " + (tmp / "run").string(), "sound " + cache,
        "render " + cache, "export " + cache + " --format obj"}) {
    const auto r = runCrumple(args);
    EXPECT_EQ(r.status, 0) << args << "\n" << r.output;
  }
  EXPECT_TRUE(fs::exists(shot / "sound.wav"));
  EXPECT_TRUE(fs::exists(tmp / "run/frames/0006.png"));
}
