#pragma once
// How polygonal a drawn sheet's silhouettes look (docs/RENDERING.md
// "Refinement"): the angle between consecutive segments of the silhouette of
// its curved regions. A silhouette segment is a sheet border edge or a
// contour edge (one triangle beside it faces the camera, the other faces
// away, for the frame's pinhole camera) of a curved-region triangle, at
// least minSegmentPx long on screen. The angle is taken in space: the kink a
// viewer sees when looking across the curve (in the image itself a curve
// seen edge-on turns by up to 180 degrees however smooth it is). Joints are
// where two border segments (not at a corner of the pattern's outline) or
// two contour segments meet; where a contour reaches the border the
// silhouette has a corner by nature.
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::pipeline {

struct SilhouetteTurning {
  // The largest angle (rad) where two silhouette segments of curved-region
  // triangles meet.
  double curved = 0.0;
  // The same where a curved region's silhouette meets another region's (a
  // run's border ruling).
  double border = 0.0;
  int joints = 0;  // joints measured in `curved`
};

SilhouetteTurning silhouetteTurning(const mesh::SheetMesh& sheet, const render::Camera& camera,
                                    double minSegmentPx = 0.5);

}  // namespace crumple::pipeline
