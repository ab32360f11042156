#pragma once
// `crumple export CACHE --format obj|ply|gltf|usda`: the cached
// frames as files that DCC tools open, made from the cache alone, so a farm
// can export any frame range in parallel and retry it. docs/EXPORT.md.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline {

enum class ExportFormat { Obj, Ply, Gltf, Usda };
// "obj", "ply", "gltf" or "usda"; throws InputError naming --format otherwise.
ExportFormat parseExportFormat(const std::string& text);
const char* exportFormatName(ExportFormat format);

struct ExportOptions {
  ExportFormat format = ExportFormat::Obj;
  std::string outDir;                // empty: <cache folder>/export/<format>
  std::optional<FrameRange> frames;  // default: every cached frame
  mesh::RefineOptions refine;        // the crumpling model's curved regions (refine.hpp): auto
  std::FILE* log = stderr;           // progress; nullptr: a quiet run
  int interactive = -1;              // -1: detect a terminal on `log`
};

struct ExportReport {
  std::string outDir;
  int frames = 0;                  // frames exported
  int tornFrames = 0;              // of which with a tear texture (OBJ)
  int refinedFrames = 0;           // of which with curved regions refined
  int topologies = 0;              // USDA: topology time samples (where it changed)
  std::vector<std::string> files;  // every file written, in order
  std::vector<std::string> notes;  // e.g. a cache recovered without its footer
  double ms = 0.0;
};

// Writes the export into options.outDir (created when missing), every file
// atomically (a temporary file, then rename); identical caches give
// identical bytes.
//   obj:  NNNN.obj per frame; paper.mtl shared by the frames without tears,
//         NNNN.mtl and NNNN_tears.png (map_d) for a frame with a TEAR block
//   ply:  NNNN.ply per frame (binary little-endian)
//   gltf: NNNN.glb per frame, and shot.glb with every frame as a node
//   usda: shot.usda
// The shot files are named shot.glb / shot.usda when every cached frame is
// exported, shot_A-B.glb / shot_A-B.usda for a range. Throws InputError for a
// range outside the cached frames (naming them), an empty cache, an
// unwritable folder or one another crumple is writing into (OutputLock: a
// range shares it with other ranges), CorruptDataError for a damaged frame.
ExportReport exportCache(const std::string& cachePath, const ExportOptions& options);

}  // namespace crumple::pipeline
