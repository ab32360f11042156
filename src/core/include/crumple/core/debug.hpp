#pragma once
// Developer switches: traces and checks a developer turns on from the
// command line (`crumple simulate SCENE --debug newton,geometry=2,...`, see
// parseDebugOptions), one set for the process, set before a shot starts and
// read by the stages that trace. Off by default; none changes a result.
#include <string>
#include <string_view>

namespace crumple {

struct DebugOptions {
  bool newton = false;      // sim: every Newton iteration of the elastic step
  int geometry = 0;         // paper: the geometric step's trace per animation step, levels 1-3
  bool tear = false;        // model: every tear candidate's Griffith test, every frame
  bool invariants = false;  // paper: S_G's region invariants after every geometric step
  std::string dump;         // paper: an OBJ file the S_P of a failed animation step goes to
};

// The process's switches (all off until setDebugOptions).
const DebugOptions& debugOptions();
void setDebugOptions(DebugOptions options);

// "newton,geometry=2,tear,invariants,dump=FILE" (comma-separated; geometry
// alone is level 1). Throws InputError("--debug", ...) naming an unknown
// switch or a bad value.
DebugOptions parseDebugOptions(std::string_view text);

}  // namespace crumple
