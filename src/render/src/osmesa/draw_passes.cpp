// The rasteriser's per-frame steps: the geometry uploads, the shadow map,
// the main pass, the structure overlay and the read-back (osmesa_impl.hpp).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>

#include "osmesa_impl.hpp"

namespace crumple::render {

using gl::kMaxLights;
using gl::PatchVertex;
using gl::Vertex;

namespace {

// The lights as the main pass's uniform arrays.
struct LightUniforms {
  // Directional (and sun): unit vector towards the light (w = 0); point and
  // area: position relative to the origin (w = 1).
  std::array<GLfloat, 4 * kMaxLights> vec{};
  std::array<GLfloat, 3 * kMaxLights> radiance{};  // colour * intensity
  // Area lights: unit normal, w = 1; others zero.
  std::array<GLfloat, 4 * kMaxLights> areaNormal{};
};

// Packs the render geometry's lights (at most kMaxLights). An area light is a
// point light at its centre whose intensity falls off with the cosine to its
// normal (view.hpp).
LightUniforms packLights(const std::vector<Light>& lights) {
  LightUniforms u;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    Vec4 v;
    if (l.kind == Light::Kind::Directional)
      v << -l.direction.normalized(), 0.0;
    else
      v << l.position, 1.0;
    const Vec3 rad = l.color * l.intensity;
    for (std::size_t k = 0; k < 4; ++k) u.vec[i * 4 + k] = static_cast<GLfloat>(v[k]);
    for (std::size_t k = 0; k < 3; ++k) u.radiance[i * 3 + k] = static_cast<GLfloat>(rad[k]);
    if (l.kind == Light::Kind::Area) {
      const Vec3 n = l.direction.normalized();
      for (std::size_t k = 0; k < 3; ++k)
        u.areaNormal[i * 4 + k] = static_cast<GLfloat>(n[static_cast<Eigen::Index>(k)]);
      u.areaNormal[i * 4 + 3] = 1.0f;
    }
  }
  return u;
}

// Sets the attributes a paper vertex and a tear-patch vertex share.
template <typename V>
void setPaperVertex(V& v, const detail::Float3& position, const detail::Float3& normal,
                    const detail::Float2& uv) {
  for (std::size_t c = 0; c < 3; ++c) {
    v.pos[c] = position[c];
    v.normal[c] = normal[c];
  }
  v.uv[0] = uv[0];
  v.uv[1] = uv[1];
}

}  // namespace

void OsmesaRenderer::Impl::uploadSheet(const detail::RenderGeometry& g,
                                       const mesh::SheetMesh& sheet, const mesh::TearAtlas& tears,
                                       bool torn) {
  // Three vertices per triangle: the shading normals are split across
  // creases and around sharp vertices (shadingNormals).
  vertices.clear();
  vertices.reserve(sheet.triangles.size() * 3);
  for (const std::size_t t : g.drawnTriangles)
    for (std::size_t k = 0; k < 3; ++k) {
      const auto i = static_cast<std::size_t>(sheet.triangles[t][k]);
      setPaperVertex(vertices.emplace_back(), g.positions[i],
                     detail::toFloat3(g.cornerNormals[t][k]), g.uvs[i]);
    }
  glBindVertexArray(paperVao);
  glBindBuffer(GL_ARRAY_BUFFER, paperVbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)),
               vertices.data(), GL_STREAM_DRAW);
  // The tear patches (thesis 3.3.4, Fig. 3.25): the triangle and its
  // support quads, cut by the patch's mask (normalised atlas coordinates).
  patchVertices.clear();
  if (!torn) return;
  const Vec2 atlasSize(tears.width, tears.height);
  for (const detail::PatchPiece& piece : g.patchPieces)
    for (const detail::PatchCorner& c : piece.corners) {
      PatchVertex& v = patchVertices.emplace_back();
      setPaperVertex(v, c.position, c.normal, c.uv);
      const Vec2 m = c.atlas.cwiseQuotient(atlasSize);
      v.maskUv[0] = static_cast<float>(m.x());
      v.maskUv[1] = static_cast<float>(m.y());
    }
  glBindVertexArray(patchVao);
  glBindBuffer(GL_ARRAY_BUFFER, patchVbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(patchVertices.size() * sizeof(PatchVertex)),
               patchVertices.data(), GL_STREAM_DRAW);
  uploadMask(tears);
}

void OsmesaRenderer::Impl::uploadProps(const detail::RenderGeometry& g) {
  propVertices.clear();
  propFirst.clear();
  for (const detail::PropGeometry& prop : g.props) {
    propFirst.push_back(static_cast<GLint>(propVertices.size()));
    for (std::size_t i = 0; i < prop.mesh->triangles.size(); ++i)
      for (const int vi : prop.mesh->triangles[i]) {
        Vertex v{};
        for (std::size_t k = 0; k < 3; ++k) {
          v.pos[k] = prop.vertices[static_cast<std::size_t>(vi)][k];
          v.normal[k] = prop.faceNormals[i][k];
        }
        propVertices.push_back(v);
      }
  }
  propFirst.push_back(static_cast<GLint>(propVertices.size()));
  if (!propVertices.empty()) {
    glBindVertexArray(propVao);
    glBindBuffer(GL_ARRAY_BUFFER, propVbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(propVertices.size() * sizeof(Vertex)),
                 propVertices.data(), GL_STREAM_DRAW);
  }
}

void OsmesaRenderer::Impl::uploadGround(const detail::RenderGeometry& g) {
  if (g.ground) {
    std::array<Vertex, 6> quad{};
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; ++i) {
      const Vec3& c = (*g.ground)[static_cast<std::size_t>(order[i])];
      Vertex& v = quad[static_cast<std::size_t>(i)];
      for (int k = 0; k < 3; ++k) v.pos[k] = static_cast<float>(c[k]);
      v.normal[0] = 0.0f;
      v.normal[1] = 1.0f;
      v.normal[2] = 0.0f;
      v.uv[0] = v.uv[1] = 0.0f;
    }
    glBindVertexArray(groundVao);
    glBindBuffer(GL_ARRAY_BUFFER, groundVbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(sizeof(quad)), quad.data(),
                 GL_STREAM_DRAW);
  }
  glBindVertexArray(0);
}

gl::ShadowProjection OsmesaRenderer::Impl::drawShadowMap(const detail::RenderGeometry& g,
                                                         const mesh::SheetMesh& sheet,
                                                         const Light& key, bool alphaCut) {
  // Casters: the paper and the props; receivers: those and the ground. The
  // sheet's vertices relative to the origin keep x and y in double and round
  // z to float: the rasteriser's source rounded all three, but g++ 12 at -O3
  // folds the float round trip of the first two (vectorised) coordinates,
  // and every preview image so far was drawn with the map this fits.
  std::vector<Vec3> receivers;
  receivers.reserve(sheet.positions.size() + propVertices.size() + patchVertices.size() + 4);
  for (const Vec3& p : sheet.positions) {
    const Vec3 q = p - g.origin;
    receivers.emplace_back(q.x(), q.y(), static_cast<double>(static_cast<float>(q.z())));
  }
  for (const Vertex& v : propVertices) receivers.emplace_back(v.pos[0], v.pos[1], v.pos[2]);
  for (const PatchVertex& v : patchVertices) receivers.emplace_back(v.pos[0], v.pos[1], v.pos[2]);
  const std::size_t nv = receivers.size();
  if (g.ground)
    for (const Vec3& c : *g.ground) receivers.push_back(c);
  const gl::ShadowProjection shadow = gl::fitShadowProjection(key, receivers, nv, shadowSize);

  glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo);
  glViewport(0, 0, shadowSize, shadowSize);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glClearDepth(1.0);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(2.0f, 4.0f);  // slope-scaled depth bias against self-shadow acne
  const GLuint paperShadow = alphaCut ? shadowCutProgram : shadowProgram;
  glUseProgram(paperShadow);
  const auto lightMatrix = gl::toGl(shadow.lightViewProj);
  glUniformMatrix4fv(glGetUniformLocation(paperShadow, "u_lightViewProj"), 1, GL_FALSE,
                     lightMatrix.data());
  glBindVertexArray(paperVao);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices.size()));
  if (!patchVertices.empty()) {
    const GLuint patchShadow = alphaCut ? shadowMaskCutProgram : shadowMaskProgram;
    glUseProgram(patchShadow);
    glUniformMatrix4fv(glGetUniformLocation(patchShadow, "u_lightViewProj"), 1, GL_FALSE,
                       lightMatrix.data());
    glBindVertexArray(patchVao);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(patchVertices.size()));
  }
  if (!propVertices.empty()) {
    glUseProgram(shadowProgram);
    glUniformMatrix4fv(glGetUniformLocation(shadowProgram, "u_lightViewProj"), 1, GL_FALSE,
                       lightMatrix.data());
    glBindVertexArray(propVao);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(propVertices.size()));
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
  return shadow;
}

void OsmesaRenderer::Impl::drawMainPass(const RenderScene& scene, const detail::RenderGeometry& g,
                                        const MainPass& pass) {
  glBindFramebuffer(GL_FRAMEBUFFER, msFbo);
  glViewport(0, 0, width, height);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  if (samples > 0) glEnable(GL_MULTISAMPLE);
  // Transparent black: the resolve then holds coverage-weighted colour and
  // coverage, turned into straight alpha by readBack.
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  const LightUniforms lights = packLights(g.lights);
  const auto numLights = static_cast<int>(g.lights.size());
  const bool transmit = scene.paper.transmittance > 0.0;
  const auto vp = gl::toGl(pass.viewProj);
  const auto lvp = gl::toGl(pass.shadow.lightViewProj);

  // What: 0 the ground, 1 a prop (colour), 2 the paper, 3 the tear patches.
  auto draw = [&](int what, const Vec3& color, GLint first, GLsizei count) {
    const bool plain = what < 2;
    const GLuint program =
        mainProgram(numLights, pass.keyLight, pass.keyIsPoint, plain, pass.triColors && !plain,
                    pass.alphaCut && !plain, transmit && !plain, pass.albedo, what == 3);
    glUseProgram(program);
    auto loc = [&](const char* name) { return glGetUniformLocation(program, name); };
    auto set3 = [&](const char* name, const Vec3& v) {
      glUniform3f(loc(name), static_cast<float>(v.x()), static_cast<float>(v.y()),
                  static_cast<float>(v.z()));
    };
    glUniformMatrix4fv(loc("u_viewProj"), 1, GL_FALSE, vp.data());
    glUniformMatrix4fv(loc("u_lightViewProj"), 1, GL_FALSE, lvp.data());
    set3("u_frontColor", scene.paper.frontColor);
    set3("u_backColor", scene.paper.backColor);
    set3("u_groundColor", color);
    set3("u_ambient", (scene.environment.intensity * scene.environment.color).cwiseMax(0.0));
    set3("u_cameraPos", g.camera.position);
    glUniform1f(loc("u_transmittance"), static_cast<float>(scene.paper.transmittance));
    glUniform4fv(loc("u_lightVec"), numLights, lights.vec.data());
    glUniform3fv(loc("u_lightRadiance"), numLights, lights.radiance.data());
    glUniform4fv(loc("u_lightAreaNormal"), numLights, lights.areaNormal.data());
    glUniform1f(loc("u_shadowTexelWorld"), static_cast<float>(pass.shadow.texelWorld));
    glUniform1f(loc("u_shadowTexel"), 1.0f / static_cast<float>(shadowSize));
    if (what == 0) {
      // Pushed back a little so that paper lying exactly on it wins the depth test.
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.0f, 2.0f);
      glBindVertexArray(groundVao);
      glDrawArrays(GL_TRIANGLES, 0, 6);
      glDisable(GL_POLYGON_OFFSET_FILL);
    } else {
      glBindVertexArray(what == 1 ? propVao : what == 2 ? paperVao : patchVao);
      glDrawArrays(GL_TRIANGLES, first, count);
    }
  };
  if (scene.ground.enabled) draw(0, scene.ground.color, 0, 6);
  for (std::size_t i = 0; i < scene.props.size(); ++i)
    if (propFirst[i + 1] > propFirst[i])
      draw(1, scene.props[i].color, propFirst[i], propFirst[i + 1] - propFirst[i]);
  if (pass.hasPaper) draw(2, Vec3::Zero(), 0, static_cast<GLsizei>(vertices.size()));
  if (!patchVertices.empty()) draw(3, Vec3::Zero(), 0, static_cast<GLsizei>(patchVertices.size()));
  glBindVertexArray(0);
}

void OsmesaRenderer::Impl::drawOverlay(const detail::OverlayGeometry& g) {
  if (g.lines.empty() && g.points.empty()) return;
  glUseProgram(overlayProgram);
  glBindVertexArray(overlayVao);
  glBindBuffer(GL_ARRAY_BUFFER, overlayVbo);
  auto drawTriangles = [](const std::vector<detail::OverlayVertex>& v) {
    if (v.empty()) return;
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(v.size() * sizeof(v[0])), v.data(),
                 GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(v.size()));
  };
  drawTriangles(g.lines);
  glDisable(GL_DEPTH_TEST);
  drawTriangles(g.points);
  glEnable(GL_DEPTH_TEST);
  glBindVertexArray(0);
}

ImageRGBA8 OsmesaRenderer::Impl::readBack(const Vec3& background) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolveFbo);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, resolveFbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  readback.resize(static_cast<std::size_t>(width) * height * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, readback.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  gl::checkGl("OsmesaRenderer::render");

  // GL rows are bottom-up; the image's are top-down. The resolved colour is
  // coverage-weighted (premultiplied): divide by coverage for straight alpha;
  // uncovered pixels carry the background colour with alpha 0.
  const std::array<std::uint8_t, 3> bg = {
      linearToSrgb8(background.x()), linearToSrgb8(background.y()), linearToSrgb8(background.z())};
  ImageRGBA8 out(width, height);
  const std::size_t rowBytes = static_cast<std::size_t>(width) * 4;
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* src = readback.data() + static_cast<std::size_t>(height - 1 - y) * rowBytes;
    std::uint8_t* dst = out.at(0, y);
    for (int x = 0; x < width; ++x, src += 4, dst += 4) {
      const unsigned a = src[3];
      if (a == 0) {
        dst[0] = bg[0];
        dst[1] = bg[1];
        dst[2] = bg[2];
        dst[3] = 0;
      } else if (a == 255) {
        std::memcpy(dst, src, 4);
      } else {
        for (int k = 0; k < 3; ++k)
          dst[k] = static_cast<std::uint8_t>(std::min(255u, (src[k] * 255u + a / 2) / a));
        dst[3] = static_cast<std::uint8_t>(a);
      }
    }
  }
  return out;
}

}  // namespace crumple::render
