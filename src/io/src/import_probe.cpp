// The forked import probe (import_probe.hpp; docs/FUZZING.md).
#include "import_probe.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "crumple/core/error.hpp"

// Present only when a sanitizer runtime is linked (weak: null otherwise). The
// child clears the death callback so that a sanitizer report inside assimp
// only ends the child (libFuzzer's callback would record it as the parent's
// crash).
extern "C" void __sanitizer_set_death_callback(void (*callback)()) __attribute__((weak));

namespace crumple::io::detail {

namespace {

constexpr int kChildDone = 0;
constexpr int kChildThrew = 3;
constexpr int kChildRejected = 4;
constexpr std::size_t kMaxReason = 4000;   // bytes of the importer's reason passed back
constexpr std::size_t kKeptOutput = 4096;  // bytes of the child's stderr kept for the message

// The child: default actions for the fatal signals (no handler of the parent,
// a sanitizer's or libFuzzer's, runs), no core file, stderr into the pipe.
[[noreturn]] void runChild(int errWrite, int resultWrite,
                           const std::function<std::string()>& import, std::size_t memoryLimit) {
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGSYS}) {
    std::signal(sig, SIG_DFL);
  }
  sigset_t fatal;
  sigemptyset(&fatal);
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGSYS}) {
    sigaddset(&fatal, sig);
  }
  sigprocmask(SIG_UNBLOCK, &fatal, nullptr);
  const rlimit noCore{0, 0};
  setrlimit(RLIMIT_CORE, &noCore);
  if (__sanitizer_set_death_callback) {
    __sanitizer_set_death_callback(nullptr);
  } else if (memoryLimit > 0) {
    const rlimit space{memoryLimit, memoryLimit};
    setrlimit(RLIMIT_AS, &space);
  }
  dup2(errWrite, STDERR_FILENO);
  int code = kChildDone;
  try {
    std::string reason = import();
    if (!reason.empty()) {
      code = kChildRejected;
      reason.resize(std::min(reason.size(), kMaxReason));  // fits the pipe's buffer
      const ssize_t written = write(resultWrite, reason.data(), reason.size());
      (void)written;
    }
  } catch (...) {
    code = kChildThrew;
  }
  _exit(code);  // no atexit handlers, no flushing of the parent's buffers
}

// The line of the child's stderr that says what went wrong: the first
// assertion or sanitizer error, else the last line.
std::string diagnosticLine(const std::string& text) {
  std::string chosen;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    begin = end + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) continue;
    if (line.find("ai_assert") != std::string::npos || line.find("ERROR:") != std::string::npos) {
      chosen = line;
      break;
    }
    chosen = line;
  }
  if (chosen.size() > 300) chosen = chosen.substr(0, 300) + "...";
  return chosen;
}

}  // namespace

std::chrono::milliseconds importDeadline() {
  if (const char* env = std::getenv("CRUMPLE_IMPORT_TIMEOUT"); env && *env) {
    char* end = nullptr;
    const double seconds = std::strtod(env, &end);
    if (end && *end == '\0' && seconds > 0.0 && seconds < 1e6) {
      return std::chrono::milliseconds(static_cast<long long>(seconds * 1000.0));
    }
  }
  return std::chrono::seconds(600);
}

std::size_t importMemoryLimit() {
  if (const char* env = std::getenv("CRUMPLE_IMPORT_MEMORY_MB"); env && *env) {
    char* end = nullptr;
    const double mb = std::strtod(env, &end);
    if (end && *end == '\0' && mb > 0.0 && mb < 1e9) {
      return static_cast<std::size_t>(mb * 1024.0 * 1024.0);
    }
  }
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(pageSize) / 2;
}

std::optional<std::string> probeInChild(const std::string& path,
                                        const std::function<std::string()>& import,
                                        std::chrono::milliseconds deadline,
                                        std::size_t memoryLimit) {
  int fds[2];
  int result[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return std::nullopt;
  if (pipe2(result, O_CLOEXEC | O_NONBLOCK) != 0) {
    close(fds[0]);
    close(fds[1]);
    return std::nullopt;
  }
  const pid_t pid = fork();
  if (pid < 0) {
    for (const int fd : {fds[0], fds[1], result[0], result[1]}) close(fd);
    return std::nullopt;
  }
  if (pid == 0) {
    close(fds[0]);
    close(result[0]);
    runChild(fds[1], result[1], import, memoryLimit);
  }
  close(fds[1]);
  close(result[1]);

  // Collect the child's stderr (its tail) until it exits or the deadline passes.
  using Clock = std::chrono::steady_clock;
  const Clock::time_point until = Clock::now() + deadline;
  std::string output;
  int readEnd = fds[0];
  int status = 0;
  bool exited = false;
  bool timedOut = false;
  while (!exited) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
    if (left.count() <= 0) {
      timedOut = true;
      break;
    }
    pollfd p{readEnd, POLLIN, 0};
    // Woken at once by the child's output or its exit (the pipe closes);
    // after that, the child is reaped within a millisecond of ending.
    const int waitMs = static_cast<int>(std::min<long long>(left.count(), readEnd >= 0 ? 20 : 1));
    const int ready = poll(&p, readEnd >= 0 ? 1 : 0, waitMs);
    if (ready > 0 && readEnd >= 0) {
      char buf[1024];
      const ssize_t n = read(readEnd, buf, sizeof buf);
      if (n > 0) {
        output.append(buf, static_cast<std::size_t>(n));
        if (output.size() > kKeptOutput) output.erase(0, output.size() - kKeptOutput);
      } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
        close(readEnd);
        readEnd = -1;
      }
    }
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid)
      exited = true;
    else if (done < 0 && errno != EINTR) {
      exited = true;
      status = 0;
    }
  }
  // The child is gone: take what is left in the pipe.
  while (readEnd >= 0) {
    pollfd p{readEnd, POLLIN, 0};
    char buf[1024];
    const ssize_t n = poll(&p, 1, 0) > 0 ? read(readEnd, buf, sizeof buf) : 0;
    if (n <= 0) break;
    output.append(buf, static_cast<std::size_t>(n));
    if (output.size() > kKeptOutput) output.erase(0, output.size() - kKeptOutput);
  }
  if (readEnd >= 0) close(readEnd);
  // The importer's reason, when the child wrote one (it has ended: no blocking).
  std::string reason;
  if (!timedOut) {
    char buf[1024];
    for (ssize_t n; (n = read(result[0], buf, sizeof buf)) > 0;) {
      reason.append(buf, static_cast<std::size_t>(n));
    }
  }
  close(result[0]);
  if (timedOut) {
    kill(pid, SIGKILL);
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", static_cast<double>(deadline.count()) / 1000.0);
    throw InputError(path, std::string("the importer (assimp) did not finish within ") + seconds +
                               " s (CRUMPLE_IMPORT_TIMEOUT); the file is malformed or too large");
  }
  const std::string said = diagnosticLine(output);
  const std::string detail = said.empty() ? "" : " (assimp said: " + said + ")";
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* name = strsignal(sig);
    throw InputError(path, "the importer (assimp) crashed on this file with signal " +
                               std::to_string(sig) + " (" + (name ? name : "?") + ")" + detail +
                               "; the file is malformed or hits an assimp bug");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kChildRejected) {
    return reason.empty() ? std::string("the importer gave no reason") : reason;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) != kChildDone) {
    throw InputError(path, "the importer (assimp) failed on this file (exit status " +
                               std::to_string(WEXITSTATUS(status)) + ")" + detail +
                               "; the file is malformed or hits an assimp bug");
  }
  return std::string();
}

}  // namespace crumple::io::detail
