#include "crumple/pipeline/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "crumple/core/error.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;
namespace {

// The pids that hold an flock on the open file `fd` as the kernel lists
// them (/proc/locks: "1: FLOCK  ADVISORY  WRITE <pid> <major>:<minor>:<inode>
// 0 EOF", the device numbers in hex); empty where it cannot tell (no
// /proc, a lock held on another machine of a network file system).
std::vector<long> kernelHolders(int fd) {
  std::vector<long> pids;
  struct stat st {};
  if (::fstat(fd, &st) != 0) return pids;
  std::ifstream in("/proc/locks");
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string index, kind, advisory, access, where;
    long pid = 0;
    if (!(words >> index >> kind >> advisory >> access >> pid >> where) || kind != "FLOCK")
      continue;  // another kind of lock, or a waiter ("-> FLOCK ...")
    unsigned devMajor = 0, devMinor = 0;
    unsigned long inode = 0;
    if (std::sscanf(where.c_str(), "%x:%x:%lu", &devMajor, &devMinor, &inode) != 3) continue;
    if (pid > 0 && inode == st.st_ino && devMajor == major(st.st_dev) &&
        devMinor == minor(st.st_dev) && std::find(pids.begin(), pids.end(), pid) == pids.end())
      pids.push_back(pid);
  }
  return pids;
}

// The pid a holder wrote into the lock file, or -1 when it has none (yet).
long holderPid(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  if (n <= 0) return -1;
  long pid = -1;
  const std::string_view s(text, static_cast<std::size_t>(n));
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), pid);
  return ec == std::errc() && end != s.data() && pid > 0 ? pid : -1;
}

// A holder writes its pid right after it takes the lock: a refused writer
// that finds none yet waits a moment for it.
long waitForHolderPid(int fd) {
  long pid = holderPid(fd);
  for (int k = 0; pid < 0 && k < 10; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    pid = holderPid(fd);
  }
  return pid;
}

void writePid(int fd) {
  const std::string text = std::to_string(::getpid()) + "\n";
  // The pid is for the message of a refused writer only: a failure to write
  // it leaves the lock held all the same.
  if (::ftruncate(fd, 0) == 0) (void)!::pwrite(fd, text.data(), text.size(), 0);
}

// errno values of a file system that cannot lock (some network ones).
bool lockingUnsupported(int err) {
  return err == ENOLCK || err == EOPNOTSUPP || err == ENOSYS || err == EINVAL;
}

}  // namespace

namespace {

// The temporaries an earlier writer left in `dir` when it was killed between
// writing a file and renaming it into place (NAME.tmp, NAME.PID.tmp,
// NAME.tmp.mp4). Only an exclusive holder removes them: no other crumple
// writes there while it holds the folder.
void removeStaleTemporaries(const std::string& dir) {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool temporary = name.ends_with(".tmp") || name.ends_with(".tmp.mp4");
    std::error_code entryError;
    if (temporary && e.is_regular_file(entryError)) fs::remove(e.path(), entryError);
  }
}

}  // namespace

OutputLock::OutputLock(const std::string& dir, Mode mode)
    : dir_(dir.empty() ? std::string(".") : dir), mode_(mode) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw InputError(dir_, "cannot create the folder: " + ec.message());
  const fs::path file = fs::path(dir_) / kOutputLockFile;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0)
    throw InputError(file.string(),
                     std::string("cannot create the folder's lock file: ") + std::strerror(errno));
  const int operation = (mode == Mode::Exclusive ? LOCK_EX : LOCK_SH) | LOCK_NB;
  int result = 0;
  do {
    result = ::flock(fd_, operation);
  } while (result != 0 && errno == EINTR);
  if (result == 0) {
    held_ = true;
    writePid(fd_);
    if (mode == Mode::Exclusive) removeStaleTemporaries(dir_);
    return;
  }
  const int err = errno;
  if (lockingUnsupported(err)) return;  // written unlocked, as before locks existed
  if (err != EWOULDBLOCK) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(file.string(), std::string("cannot lock the folder: ") + std::strerror(err));
  }
  // Who holds it: the kernel's list, else the pid the holder wrote (shared
  // holders overwrite each other's, the kernel knows them all).
  std::vector<long> pids = kernelHolders(fd_);
  if (pids.empty())
    if (const long pid = waitForHolderPid(fd_); pid > 0) pids.push_back(pid);
  ::close(fd_);
  fd_ = -1;
  std::string holders = pids.size() > 1 ? "pids " : "pid ";
  for (std::size_t k = 0; k < pids.size(); ++k)
    holders += (k > 0 ? ", " : "") + std::to_string(pids[k]);
  if (pids.empty()) holders += "unknown";
  throw InputError(dir_ + " is being written by another crumple (" + holders +
                   "); wait for it or choose another --out");
}

OutputLock::~OutputLock() { release(); }

OutputLock::OutputLock(OutputLock&& other) noexcept
    : dir_(std::move(other.dir_)),
      fd_(std::exchange(other.fd_, -1)),
      mode_(other.mode_),
      held_(std::exchange(other.held_, false)) {}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
  if (this != &other) {
    release();
    dir_ = std::move(other.dir_);
    fd_ = std::exchange(other.fd_, -1);
    mode_ = other.mode_;
    held_ = std::exchange(other.held_, false);
  }
  return *this;
}

void OutputLock::release() noexcept {
  if (fd_ < 0) return;
  // An exclusive holder empties the file first: a lock file left behind
  // names nobody. Shared holders leave it (another may still hold it).
  if (held_ && mode_ == Mode::Exclusive) (void)!::ftruncate(fd_, 0);
  ::close(fd_);  // closing the descriptor releases the flock
  fd_ = -1;
  held_ = false;
}

}  // namespace crumple::pipeline
