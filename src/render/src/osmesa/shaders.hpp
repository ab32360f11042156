#pragma once
// Private to the rasteriser: its GLSL 330 programs (shaders.cpp has the
// sources and what each variant compiles in or out).
#include <string>

#include "gl.hpp"

namespace crumple::render::gl {

// The main pass's vertex and fragment shaders (paper, ground, props).
extern const char* const kMainVertex;
extern const char* const kMainFragment;
// The structure overlay's flat screen-space triangles.
extern const char* const kOverlayVertex;
extern const char* const kOverlayFragment;
// The shadow map's depth-only pass.
extern const char* const kShadowVertex;
extern const char* const kShadowFragment;

// Compiles the two shaders, each after "#version 330 core" and `defines`,
// and links them. Throws std::runtime_error with GL's log on failure.
GLuint linkProgram(const std::string& defines, const char* vs, const char* fs);

}  // namespace crumple::render::gl
