#pragma once
// Containment of crashes inside assimp (docs/FUZZING.md "Crashes inside
// assimp"). assimp 5.2.5 (Debian 12) aborts on its own assertions and reads
// out of bounds on some malformed glTF, FBX and COLLADA files, and we cannot
// patch it; some files make it allocate tens of gigabytes. So
// AnimationScene::load first runs the same import in a forked child process
// with a memory limit; only when the child imported the file does the import
// run again in this process. A child killed by a signal (or a sanitizer
// report), or one that runs past the deadline, becomes an InputError naming
// the file.
#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

namespace crumple::io::detail {

// Seconds the child may take: CRUMPLE_IMPORT_TIMEOUT (a positive number of
// seconds) or 600.
std::chrono::milliseconds importDeadline();

// Address space the child may use: CRUMPLE_IMPORT_MEMORY_MB (a positive
// number of MB) or half the machine's physical memory. Not applied under a
// sanitizer (its shadow memory is already mapped; ASan's own
// max_allocation_size_mb limits it there).
std::size_t importMemoryLimit();

// Runs `import` in a forked child under `memoryLimit` bytes of address space;
// `import` returns "" when it imported the file, else the importer's reason.
// Returns nullopt when no child could be started (the caller imports
// in-process, as without the probe), otherwise what `import` returned: the
// caller imports in-process only after "", so a file that failed (for
// example, ran out of memory) in the child is never retried in this process.
// Throws InputError naming `path` when the child died (the signal and the
// line of its stderr that says why are in the message) or did not finish
// within `deadline` (it is killed).
std::optional<std::string> probeInChild(const std::string& path,
                                        const std::function<std::string()>& import,
                                        std::chrono::milliseconds deadline,
                                        std::size_t memoryLimit);

}  // namespace crumple::io::detail
