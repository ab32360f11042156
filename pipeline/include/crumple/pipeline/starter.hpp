#pragma once
// `crumple init DIR`: a starter shot for users without a DCC at hand. Writes
// DIR/scene.toml, commented key by key, and DIR/gather.gltf, the handles'
// animation: a 20 cm sheet of office paper held level by its four corners,
// which draw in towards its middle and lift while their tangent planes tilt
// out (a gather), with a camera, two lights, a ground and a soundtrack. It
// runs as is (`crumple run DIR`).
#include <filesystem>

namespace crumple::pipeline {

// Writes the starter shot into `dir` (created when missing). Throws
// InputError when `dir` already holds a scene.toml or a gather.gltf and
// `overwrite` is false, or when it cannot be written.
void writeStarterShot(const std::filesystem::path& dir, bool overwrite);

}  // namespace crumple::pipeline
