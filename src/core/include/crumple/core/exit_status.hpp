#pragma once
// The command line's exit-status contract (error.hpp, docs/ARCHITECTURE.md
// "The command line") for a whole program or command, in one place.
#include <functional>

namespace crumple {

// Runs `body` and returns its status; an exception becomes the status and a
// message on stderr prefixed by `program`: bad input (InputError,
// CorruptDataError) "error:", exit 2; a numerical failure "numerical
// failure:", exit 1; anything else "internal error:", exit 1.
int runWithExitStatus(const char* program, const std::function<int()>& body);

}  // namespace crumple
