#pragma once
// Render-time refinement of a cached frame of the crumpling model
// (mesh/developable.hpp, docs/RENDERING.md "Refinement"): what `render`,
// `run` and `export` draw and write instead of S_P's coarse curved strips.
#include <optional>
#include <string>

#include "crumple/cache/pcache.hpp"
#include "crumple/mesh/developable.hpp"

namespace crumple::pipeline {

// --refine: "auto" (the fold angle, and the screen where there is a camera),
// "off", or a whole number N >= 1 of sub-cells per S_G face. Throws
// InputError naming `flag` otherwise.
mesh::RefineOptions parseRefine(const std::string& text, const std::string& flag);
// "auto", "off" or "N", as parseRefine reads it.
std::string refineName(const mesh::RefineOptions& options);

// Refines `frame` in place when it has an SGEO block (a frame of the
// crumpling model) and `options` is not off: its mesh becomes the refined
// one (the source's vertices keep their indices, so the singular, junction
// and handle vertices and the rulings still name the same points), its
// TEAR patches follow their triangles and its VELO velocities (motion blur)
// cover the new vertices, interpolated in the source triangles. Returns the refinement's figures,
// or nullopt when nothing was done. Handles and singular vertices are pinned, triangles with a tear
// patch locked. Throws CorruptDataError naming the frame for an SGEO block that does not fit its
// mesh.
std::optional<mesh::RefineStats> refineFrame(cache::FrameRecord& frame,
                                             const mesh::RefineOptions& options);

}  // namespace crumple::pipeline
