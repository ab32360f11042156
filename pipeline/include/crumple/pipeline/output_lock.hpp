#pragma once
// One writer per output folder (docs/ARCHITECTURE.md "Invariants everyone keeps"): a
// command that writes into a folder holds an flock(2) on DIR/.crumple.lock
// for as long as it writes, so a second crumple writing there at the same
// time stops with a clear error instead of mixing two shots' files.
//
// The lock is the kernel's, not the file's: it goes with the process (a
// crash or a kill releases it), and a lock file left behind holds nothing
// and blocks nobody. The holder writes its pid into the file for the error
// message of the one that is refused.
//
// An exclusive holder first removes the temporaries (NAME.tmp, NAME.PID.tmp,
// NAME.tmp.mp4) a killed writer left in the folder between writing a file
// and renaming it into place.
//
// Exclusive: simulate, run, sound, export and render of a whole cache.
// Shared: render and export of a frame range (--frames), whose writers
// share the folder with each other (a farm's array tasks write their chunks
// into one frames folder side by side) but not with an exclusive writer.
#include <string>

namespace crumple::pipeline {

inline constexpr const char* kOutputLockFile = ".crumple.lock";

class OutputLock {
 public:
  enum class Mode { Exclusive, Shared };

  // Creates `dir` when missing and takes its lock without waiting. Throws
  // InputError naming the folder and the holder's pid when another writer
  // holds it ("... is being written by another crumple (pid N); wait for it
  // or choose another --out"), or when the lock file cannot be created. On
  // a file system without flock the folder is written unlocked.
  explicit OutputLock(const std::string& dir, Mode mode = Mode::Exclusive);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  OutputLock(OutputLock&& other) noexcept;
  OutputLock& operator=(OutputLock&& other) noexcept;

  const std::string& dir() const { return dir_; }
  // False on a file system that has no flock (the folder is written anyway).
  bool held() const { return held_; }

 private:
  void release() noexcept;

  std::string dir_;
  int fd_ = -1;
  Mode mode_ = Mode::Exclusive;
  bool held_ = false;
};

}  // namespace crumple::pipeline
