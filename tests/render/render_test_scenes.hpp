#pragma once
// Small scenes shared by the render tests and the render_dump helper.
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render::test {

constexpr double kSheetWidth = 0.21;
constexpr double kSheetHeight = 0.297;

// An A4 sheet lying flat in the plane Y = y, centred on the Y axis, front side
// up (+Y): pattern +x -> world +X, pattern +y -> world -Z.
mesh::SheetMesh flatSheet(double y, double maxEdge = 0.03);

// The same sheet with its right part (pattern x > kBentFlatPart) rolled up
// into a curl of radius 0.05 m around an axis parallel to Z, lifted `lift`
// above Y = 0; bentSheetPoint is where pattern point (u, v) goes.
constexpr double kBentFlatPart = 0.06;
Vec3 bentSheetPoint(double u, double v, double lift);
mesh::SheetMesh bentSheet(double lift, double maxEdge);

// Camera straight above the origin at height `height`, image up = world -Z.
Camera topCamera(double height, int width, int height_px);

// The golden scene: the bent sheet on a ground plane, a shadow-casting key
// light and a fill light, seen from the front right.
RenderScene bentScene(int width, int height);
mesh::SheetMesh bentSceneSheet();

// A structure view of a bentSheet (maxEdge 0.015): flat part green, curl
// magenta, the border between them and rulings on the grid columns of the
// curl as polylines, a red (singular) vertex on the flat part (visible from
// the bentScene camera), yellow (junction) vertices at both ends of the
// border, a black handle at pattern corner (0, 0).
StructureOverlay bentSheetStructure(const mesh::SheetMesh& sheet);

}  // namespace crumple::render::test
