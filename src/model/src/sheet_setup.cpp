#include "crumple/model/sheet_setup.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "crumple/core/debug.hpp"
#include "crumple/core/error.hpp"
#include "crumple/paper/hybrid_sheet.hpp"
#include "crumple/paper/initial_sheet.hpp"
#include "crumpling_model.hpp"
#include "elastic_model.hpp"

namespace crumple::model {

namespace {

// The scene's crumpling parameters, with the region invariants checked after
// every geometric step: always in debug builds, on request (--debug
// invariants) in release builds.
paper::CrumpleParams crumpleParamsOf(const io::SceneSpec& scene) {
  paper::CrumpleParams p = scene.crumpling;
  if (debugOptions().invariants) p.checkInvariants = true;
  return p;
}

// The crumpling model's starting S_G: the rectangle with a vertex at every
// handle's pattern point (or the sheet point under its node at the first
// frame), so handles hold exactly the point they name.
paper::InitialSheet crumplingStartSheet(const io::SceneSpec& scene,
                                        const io::AnimationScene* animation, double t0) {
  const auto& s = scene.sheet;
  if (s.kind != io::SheetSpec::Kind::Rectangle)
    throw InputError(scene.file,
                     "[model] type = \"hybrid\" needs a rectangular [sheet] (width, height); "
                     "pattern_mesh sheets run with the elastic model only");
  const Vec3 u = s.uAxis.normalized();
  const Vec3 v = s.vAxis.normalized();
  std::vector<Vec2> points;
  for (const auto& h : scene.handles) {
    if (h.patternPoint) {
      points.push_back(*h.patternPoint);
    } else if (animation != nullptr && animation->hasNode(h.node)) {
      const Vec3 x = animation->worldPose(h.node, t0).position - s.origin;
      points.push_back(
          Vec2(std::clamp(x.dot(u), 0.0, s.width), std::clamp(x.dot(v), 0.0, s.height)));
    }
  }
  return paper::makeFlatSheet(s.width, s.height, points, s.origin, u, v);
}

// A flat pattern mesh from the animation file: its plane gives the pattern.
mesh::SheetMesh importedSheet(const io::SceneSpec& scene, const io::AnimationScene* animation) {
  const auto& s = scene.sheet;
  if (animation == nullptr)
    throw InputError(scene.file, "[sheet] pattern_mesh needs an animation file");
  const auto imported = animation->mesh(s.patternMesh);
  if (!imported || imported->triangles.empty())
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh +
                                     "' is not a mesh node of " + animation->file());
  Vec3 centre = Vec3::Zero();
  for (const auto& v : imported->vertices) centre += v;
  centre /= static_cast<double>(imported->vertices.size());
  Mat3 cov = Mat3::Zero();
  for (const auto& v : imported->vertices) cov += (v - centre) * (v - centre).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 normal = eig.eigenvectors().col(0);
  Vec3 u = eig.eigenvectors().col(2);
  Vec3 v = normal.cross(u);
  double extent = 0.0, deviation = 0.0;
  mesh::SheetMesh sheet;
  for (const auto& p : imported->vertices) {
    sheet.pattern.emplace_back((p - centre).dot(u), (p - centre).dot(v));
    sheet.positions.push_back(p);
    extent = std::max(extent, (p - centre).norm());
    deviation = std::max(deviation, std::abs((p - centre).dot(normal)));
  }
  if (deviation > 1e-4 * std::max(extent, 1e-9))
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh +
                                     "' is not flat (deviates " + std::to_string(deviation) +
                                     " m from its plane)");
  Vec2 lo = sheet.pattern.front();
  for (const auto& p : sheet.pattern) lo = lo.cwiseMin(p);
  for (auto& p : sheet.pattern) p -= lo;
  for (auto t : imported->triangles) {
    // Orient every triangle counter-clockwise in the pattern.
    const Vec2 e1 = sheet.pattern[static_cast<std::size_t>(t[1])] -
                    sheet.pattern[static_cast<std::size_t>(t[0])];
    const Vec2 e2 = sheet.pattern[static_cast<std::size_t>(t[2])] -
                    sheet.pattern[static_cast<std::size_t>(t[0])];
    if (e1.x() * e2.y() - e1.y() * e2.x() < 0.0) std::swap(t[1], t[2]);
    sheet.triangles.push_back(t);
  }
  sheet.regionOfTriangle.assign(sheet.triangles.size(), 0);
  sheet.regionTypes = {mesh::RegionType::Flat};
  if (const auto problem = mesh::validate(sheet); !problem.empty())
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh + "': " + problem);
  return sheet;
}

}  // namespace

mesh::SheetMesh buildSheet(const io::SceneSpec& scene, const io::AnimationScene* animation) {
  const auto& s = scene.sheet;
  if (s.kind == io::SheetSpec::Kind::Rectangle || s.kind == io::SheetSpec::Kind::Outline) {
    const double maxEdge = s.maxEdge > 0.0 ? s.maxEdge : std::min(s.width, s.height) / 16.0;
    auto sheet = s.kind == io::SheetSpec::Kind::Rectangle
                     ? mesh::makeRectangleSheet(s.width, s.height, maxEdge)
                     : mesh::makePolygonSheet(s.outline, maxEdge);
    mesh::placePattern(sheet, s.origin, s.uAxis.normalized(), s.vAxis.normalized());
    return sheet;
  }
  return importedSheet(scene, animation);
}

ShotSheet setUpSheet(const io::SceneSpec& scene, const io::AnimationScene* animation,
                     ModelContext context, double t0) {
  context.elasticMesh = [&scene, animation] { return buildSheet(scene, animation); };
  ShotSheet out;
  out.context = std::make_shared<const ModelContext>(std::move(context));
  if (scene.model.type == io::ModelSpec::Type::Hybrid) {
    auto sheet = std::make_unique<paper::HybridSheet>(
        crumplingStartSheet(scene, animation, t0).mesh, out.context->material, out.context->sim,
        crumpleParamsOf(scene), out.context->seed);
    out.rig = std::make_unique<HandleRig>(scene, animation, sheet->physical().mesh, t0);
    auto crumpling = std::make_unique<CrumplingModel>(std::move(sheet), out.context);
    crumpling->bind(*out.rig, t0);
    out.model = std::move(crumpling);
    return out;
  }
  mesh::SheetMesh sheet = buildSheet(scene, animation);
  out.rig = std::make_unique<HandleRig>(scene, animation, sheet, t0);
  out.rig->snap(t0, sheet.positions);
  out.model = std::make_unique<ElasticModel>(std::move(sheet), out.context, *out.rig);
  return out;
}

void saveModel(StateWriter& out, const SheetModel& model) {
  out.boolean(model.crumpling());
  model.saveState(out);
}

void restoreModel(StateReader& in, std::unique_ptr<SheetModel>& model,
                  const std::shared_ptr<const ModelContext>& context, HandleRig& rig) {
  const bool crumpling = in.boolean();
  if (crumpling && !model->crumpling())
    in.fail("holds the crumpling model's state, the scene runs the elastic model");
  if (crumpling == model->crumpling()) {
    model->restoreState(in);
    return;
  }
  // A crumpling-model sheet handed over to the elastic model.
  model = ElasticModel::restored(in, context, rig);
}

}  // namespace crumple::model
