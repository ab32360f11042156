// `crumple export`: cached frames to OBJ, PLY, glTF and USDA (docs/EXPORT.md).
#include "crumple/pipeline/export.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/exporters/gltf_export.hpp"
#include "crumple/exporters/mesh_export.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/pipeline/refine.hpp"

namespace crumple::pipeline {
namespace {

namespace fs = std::filesystem;

// Creates the folder and checks that a file can be written in it.
void prepareExportDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir, "cannot create the export folder: " + ec.message());
  const fs::path probe = fs::path(dir) / ".crumple-write-probe";
  {
    std::ofstream out(probe);
    if (!out) throw InputError(dir, "the export folder is not writable");
  }
  fs::remove(probe, ec);
}

// The paper's front colour from the scene kept in the cache header; the
// presets' default when the scene cannot be read here (a note says so).
Vec3 paperColour(const cache::CacheHeader& header, const std::string& cachePath,
                 std::vector<std::string>& notes) {
  try {
    const io::SceneSpec scene =
        io::parseScene(header.sceneText, header.sceneFile + " (in " + cachePath + ")",
                       fs::path(header.sceneFile).parent_path().string(), /*checkFiles=*/false);
    return scene.paper.frontColor;
  } catch (const InputError& e) {
    notes.push_back(std::string("the paper's colour is the default one: ") + e.what());
    return io::PaperPreset{}.frontColor;
  }
}

}  // namespace

ExportFormat parseExportFormat(const std::string& text) {
  if (text == "obj") return ExportFormat::Obj;
  if (text == "ply") return ExportFormat::Ply;
  if (text == "gltf") return ExportFormat::Gltf;
  if (text == "usda") return ExportFormat::Usda;
  throw InputError("--format", "'" + text + "' is not a format (obj, ply, gltf or usda)");
}

const char* exportFormatName(ExportFormat format) {
  switch (format) {
    case ExportFormat::Obj:
      return "obj";
    case ExportFormat::Ply:
      return "ply";
    case ExportFormat::Gltf:
      return "gltf";
    case ExportFormat::Usda:
      return "usda";
  }
  return "?";
}

ExportReport exportCache(const std::string& cachePath, const ExportOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const cache::CacheReader reader(cachePath);
  if (reader.frameCount() == 0) throw InputError(cachePath, "the cache holds no frames");
  const cache::CacheHeader& header = reader.header();
  const int firstCached = reader.frameNumber(0);
  const int lastCached = reader.frameNumber(reader.frameCount() - 1);
  FrameRange range{firstCached, lastCached};
  if (options.frames) {
    range = *options.frames;
    if (range.first < firstCached || range.last > lastCached || range.last < range.first)
      throw InputError(
          cachePath, "--frames " + std::to_string(range.first) + "-" + std::to_string(range.last) +
                         " is outside the cached frames " + std::to_string(firstCached) + "-" +
                         std::to_string(lastCached));
  }
  std::vector<std::size_t> indices;  // the cached frames in the range
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const int f = reader.frameNumber(i);
    if (f >= range.first && f <= range.last) indices.push_back(i);
  }
  if (indices.empty())
    throw InputError(cachePath, "no cached frame lies in --frames " + std::to_string(range.first) +
                                    "-" + std::to_string(range.last));

  const ExportFormat format = options.format;
  ExportReport report;
  report.outDir =
      !options.outDir.empty()
          ? options.outDir
          : (fs::path(cachePath).parent_path() / "export" / exportFormatName(format)).string();
  if (std::string note = recoveredNote(reader); !note.empty()) {
    if (options.log) std::fprintf(options.log, "crumple export: note: %s\n", note.c_str());
    report.notes.push_back(std::move(note));
  }
  // One UV square for the whole shot, whatever the range: the first cached
  // frame's pattern (the sheet at rest), so farm chunks agree.
  const exporters::UvMapping uv = exporters::uvMappingOf(
      reader.readFrame(0).pattern, cachePath + ": frame " + std::to_string(firstCached));
  const Vec3 colour = paperColour(header, cachePath, report.notes);
  prepareExportDir(report.outDir);
  // A frame range shares the folder with the other ranges' exports (farm
  // chunks), the whole cache has it alone.
  const OutputLock lock(report.outDir,
                        options.frames ? OutputLock::Mode::Shared : OutputLock::Mode::Exclusive);
  const fs::path dir(report.outDir);
  const bool wholeShot = range.first <= firstCached && range.last >= lastCached;
  const std::string shotStem =
      wholeShot ? std::string("shot")
                : "shot_" + exporters::frameStem(reader.frameNumber(indices.front())) + "-" +
                      exporters::frameStem(reader.frameNumber(indices.back()));

  std::unique_ptr<exporters::GlbShot> glbShot;
  std::unique_ptr<exporters::UsdaWriter> usda;
  const std::string shotPath =
      (dir / (shotStem + (format == ExportFormat::Gltf ? ".glb" : ".usda"))).string();
  if (format == ExportFormat::Gltf)
    glbShot = std::make_unique<exporters::GlbShot>(header.fps, colour);
  if (format == ExportFormat::Usda)
    usda = std::make_unique<exporters::UsdaWriter>(shotPath, header.sceneName, header.fps);
  const bool shotFile = glbShot || usda;

  Progress progress(std::string("crumple export (") + exportFormatName(format) + ")",
                    static_cast<long>(indices.size()) + (shotFile ? 1 : 0), options.log,
                    options.interactive);
  bool sharedMtl = false;  // paper.mtl written
  const auto written = [&](const fs::path& p) { report.files.push_back(p.string()); };
  for (std::size_t k = 0; k < indices.size(); ++k) {
    cache::FrameRecord frame = reader.readFrame(indices[k]);
    if (refineFrame(frame, options.refine)) ++report.refinedFrames;
    const exporters::ExportMesh mesh = exporters::exportMesh(frame, header.fps, uv);
    const std::string stem = exporters::frameStem(frame.frame);
    switch (format) {
      case ExportFormat::Obj: {
        exporters::ObjMaterial material;
        material.diffuse = colour;
        std::string mtl = "paper.mtl";
        if (const auto texture = exporters::tearTexture(frame, uv)) {
          material.alphaTexture = stem + "_tears.png";
          mtl = stem + ".mtl";
          exporters::writePng((dir / material.alphaTexture).string(), *texture);
          written(dir / material.alphaTexture);
          exporters::writeFileAtomically((dir / mtl).string(), exporters::mtlText(material));
          written(dir / mtl);
          ++report.tornFrames;
        } else if (!sharedMtl) {
          exporters::writeFileAtomically((dir / mtl).string(), exporters::mtlText(material));
          written(dir / mtl);
          sharedMtl = true;
        }
        exporters::writeFileAtomically((dir / (stem + ".obj")).string(),
                                       exporters::objText(mesh, mtl, material.name));
        written(dir / (stem + ".obj"));
        break;
      }
      case ExportFormat::Ply:
        exporters::writeFileAtomically((dir / (stem + ".ply")).string(), exporters::plyBytes(mesh));
        written(dir / (stem + ".ply"));
        break;
      case ExportFormat::Gltf:
        exporters::writeGlb((dir / (stem + ".glb")).string(), mesh, colour);
        written(dir / (stem + ".glb"));
        glbShot->add(mesh);
        break;
      case ExportFormat::Usda:
        usda->add(mesh);
        break;
    }
    ++report.frames;
    progress.update(static_cast<long>(k + 1));
  }
  if (glbShot) glbShot->write(shotPath);
  if (usda) {
    usda->close();
    report.topologies = usda->topologySamples();
  }
  if (shotFile) {
    written(shotPath);
    progress.update(static_cast<long>(indices.size()) + 1);
  }
  progress.finish();
  report.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace crumple::pipeline
