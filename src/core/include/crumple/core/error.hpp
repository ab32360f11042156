#pragma once
// Error types and the exit-status contract of the CLI (docs/ARCHITECTURE.md "The command
// line"): InputError -> exit 2 (bad input), everything else -> exit 1.
#include <stdexcept>
#include <string>

namespace crumple {

// Bad input: a malformed or missing file, an unknown key, an impossible value.
// The message names the file and, where known, the line and the key.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  InputError(const std::string& file, const std::string& problem)
      : std::runtime_error(file + ": " + problem) {}
  InputError(const std::string& file, long line, const std::string& key, const std::string& problem)
      : std::runtime_error(file + ":" + std::to_string(line) + ": '" + key + "': " + problem) {}
};

// A numerical failure that survived substep halving. Names frame and stage.
class NumericalError : public std::runtime_error {
 public:
  NumericalError(const std::string& stage, int frame, const std::string& problem)
      : std::runtime_error("frame " + std::to_string(frame) + ", stage '" + stage +
                           "': " + problem),
        stage_(stage),
        problem_(problem),
        frame_(frame) {}
  // Without a frame (a module that does not know it); the pipeline rethrows
  // with the frame filled in.
  NumericalError(const std::string& stage, const std::string& problem)
      : std::runtime_error("stage '" + stage + "': " + problem),
        stage_(stage),
        problem_(problem),
        frame_(-1) {}
  const std::string& stage() const { return stage_; }
  const std::string& problem() const { return problem_; }
  int frame() const { return frame_; }

 private:
  std::string stage_;
  std::string problem_;
  int frame_;
};

// A file that exists but is damaged (CRC mismatch, truncated block).
class CorruptDataError : public std::runtime_error {
 public:
  explicit CorruptDataError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace crumple
