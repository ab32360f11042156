// The rasteriser's set-up: programs, vertex arrays, framebuffers, and the
// textures uploaded per frame (osmesa_impl.hpp).
#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "osmesa_impl.hpp"
#include "shaders.hpp"

namespace crumple::render {

using gl::checkFramebuffer;
using gl::checkGl;
using gl::kMainFragment;
using gl::kMainVertex;
using gl::kMaskUnit;
using gl::kMaxSamples;
using gl::kOverlayFragment;
using gl::kOverlayVertex;
using gl::kShadowFragment;
using gl::kShadowMapLarge;
using gl::kShadowMapSmall;
using gl::kShadowVertex;
using gl::linkProgram;
using gl::PatchVertex;
using gl::Vertex;

namespace {

// Enables float attribute `index` of `components` at `offset` in buffers of
// VertexType on the bound array.
template <typename VertexType>
void floatAttribute(GLuint index, GLint components, std::size_t offset) {
  glEnableVertexAttribArray(index);
  glVertexAttribPointer(index, components, GL_FLOAT, GL_FALSE,
                        static_cast<GLsizei>(sizeof(VertexType)),
                        reinterpret_cast<const void*>(offset));
}

// A new vertex array and its buffer, both bound.
void bindNewVertexArray(GLuint& vao, GLuint& vbo) {
  glGenVertexArrays(1, &vao);
  glGenBuffers(1, &vbo);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
}

// The attribute layout of a Vertex buffer (position, normal, uv) on the bound array.
void setupVertexLayout() {
  floatAttribute<Vertex>(0, 3, offsetof(Vertex, pos));
  floatAttribute<Vertex>(1, 3, offsetof(Vertex, normal));
  floatAttribute<Vertex>(2, 2, offsetof(Vertex, uv));
}

}  // namespace

OsmesaRenderer::Impl::Impl(int w, int h)
    : width(w), height(h), osmesaBuffer(static_cast<std::size_t>(w) * h * 4) {
  const gl::CurrentContext current(context, osmesaBuffer, width, height);
  if (glGetString(GL_VERSION) == nullptr)
    throw std::runtime_error(
        "OsmesaRenderer: GL calls are no-ops (is libGL linked besides OSMesa?)");
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxSize);
  if (w > maxSize || h > maxSize)
    throw std::invalid_argument("OsmesaRenderer: image larger than GL_MAX_RENDERBUFFER_SIZE " +
                                std::to_string(maxSize));
  createPrograms();
  createGeometry();
  createTargets();
  checkGl("OsmesaRenderer setup");
}

void OsmesaRenderer::Impl::createPrograms() {
  shadowProgram = linkProgram("#define ALPHA_CUT 0\n", kShadowVertex, kShadowFragment);
  shadowCutProgram = linkProgram("#define ALPHA_CUT 1\n", kShadowVertex, kShadowFragment);
  glUseProgram(shadowCutProgram);
  glUniform1i(glGetUniformLocation(shadowCutProgram, "u_tex"), 0);
  shadowMaskProgram =
      linkProgram("#define ALPHA_CUT 0\n#define TEAR_MASK 1\n", kShadowVertex, kShadowFragment);
  shadowMaskCutProgram =
      linkProgram("#define ALPHA_CUT 1\n#define TEAR_MASK 1\n", kShadowVertex, kShadowFragment);
  for (const GLuint p : {shadowMaskProgram, shadowMaskCutProgram}) {
    glUseProgram(p);
    glUniform1i(glGetUniformLocation(p, "u_tex"), 0);
    glUniform1i(glGetUniformLocation(p, "u_mask"), kMaskUnit);
  }
  overlayProgram = linkProgram("", kOverlayVertex, kOverlayFragment);
}

GLuint OsmesaRenderer::Impl::mainProgram(int numLights, int keyLight, bool keyIsPoint, bool ground,
                                         bool triColors, bool alphaCut, bool transmit, bool albedo,
                                         bool tearMask) {
  const std::array<int, 9> variant = {numLights,        keyLight,          keyIsPoint ? 1 : 0,
                                      ground ? 1 : 0,   triColors ? 1 : 0, alphaCut ? 1 : 0,
                                      transmit ? 1 : 0, albedo ? 1 : 0,    tearMask ? 1 : 0};
  const auto it = mainPrograms.find(variant);
  if (it != mainPrograms.end()) return it->second;
  const std::string defines =
      "#define NUM_LIGHTS " + std::to_string(numLights) + "\n#define KEY_LIGHT " +
      std::to_string(keyLight) + "\n#define KEY_IS_POINT " + std::to_string(variant[2]) +
      "\n#define IS_GROUND " + std::to_string(variant[3]) + "\n#define TRI_COLORS " +
      std::to_string(variant[4]) + "\n#define ALPHA_CUT " + std::to_string(variant[5]) +
      "\n#define TRANSMIT " + std::to_string(variant[6]) + "\n#define ALBEDO " +
      std::to_string(variant[7]) + "\n" + (tearMask ? "#define TEAR_MASK 1\n" : "");
  const GLuint program = linkProgram(defines, kMainVertex, kMainFragment);
  glUseProgram(program);
  glUniform1i(glGetUniformLocation(program, "u_tex"), 0);
  glUniform1i(glGetUniformLocation(program, "u_shadowMap"), 1);
  if (triColors) glUniform1i(glGetUniformLocation(program, "u_triColors"), 2);
  if (tearMask) glUniform1i(glGetUniformLocation(program, "u_mask"), kMaskUnit);
  mainPrograms.emplace(variant, program);
  return program;
}

void OsmesaRenderer::Impl::createGeometry() {
  bindNewVertexArray(paperVao, paperVbo);
  setupVertexLayout();
  bindNewVertexArray(groundVao, groundVbo);
  setupVertexLayout();
  bindNewVertexArray(propVao, propVbo);
  setupVertexLayout();
  bindNewVertexArray(patchVao, patchVbo);
  floatAttribute<PatchVertex>(0, 3, offsetof(PatchVertex, pos));
  floatAttribute<PatchVertex>(1, 3, offsetof(PatchVertex, normal));
  floatAttribute<PatchVertex>(2, 2, offsetof(PatchVertex, uv));
  floatAttribute<PatchVertex>(3, 2, offsetof(PatchVertex, maskUv));
  bindNewVertexArray(overlayVao, overlayVbo);
  const auto stride = static_cast<GLsizei>(sizeof(detail::OverlayVertex));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offsetof(detail::OverlayVertex, clip)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride,
                        reinterpret_cast<const void*>(offsetof(detail::OverlayVertex, color)));
  glBindVertexArray(0);

  glGenTextures(1, &paperTex);
  glGenTextures(1, &maskTex);
  glGenBuffers(1, &triColorBuffer);
  glGenTextures(1, &triColorTex);
}

void OsmesaRenderer::Impl::uploadTriangleColors(const std::vector<Vec3>& colors) {
  GLint maxTexels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
  if (colors.size() > static_cast<std::size_t>(maxTexels))
    throw std::invalid_argument(
        "OsmesaRenderer: overlay has more triangle colours than "
        "GL_MAX_TEXTURE_BUFFER_SIZE " +
        std::to_string(maxTexels));
  triColors.resize(colors.size() * 4);
  for (std::size_t i = 0; i < colors.size(); ++i) {
    for (std::size_t k = 0; k < 3; ++k)
      triColors[i * 4 + k] =
          static_cast<GLfloat>(std::clamp(colors[i][static_cast<Eigen::Index>(k)], 0.0, 1.0));
    triColors[i * 4 + 3] = 1.0f;
  }
  glBindBuffer(GL_TEXTURE_BUFFER, triColorBuffer);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(triColors.size() * sizeof(GLfloat)),
               triColors.data(), GL_STREAM_DRAW);
  glBindBuffer(GL_TEXTURE_BUFFER, 0);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_BUFFER, triColorTex);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, triColorBuffer);
  glActiveTexture(GL_TEXTURE0);
}

void OsmesaRenderer::Impl::createTargets() {
  GLint maxSamples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  samples = std::min(kMaxSamples, static_cast<int>(maxSamples));
  if (samples < 2) samples = 0;

  glGenRenderbuffers(1, &msColor);
  glBindRenderbuffer(GL_RENDERBUFFER, msColor);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &msDepth);
  glBindRenderbuffer(GL_RENDERBUFFER, msDepth);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
  glGenFramebuffers(1, &msFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, msFbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msColor);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msDepth);
  checkFramebuffer("multisample");

  glGenRenderbuffers(1, &resolveColor);
  glBindRenderbuffer(GL_RENDERBUFFER, resolveColor);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glGenFramebuffers(1, &resolveFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, resolveFbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolveColor);
  checkFramebuffer("resolve");

  shadowSize = std::max(width, height) > 2048 ? kShadowMapLarge : kShadowMapSmall;
  glGenTextures(1, &shadowTex);
  glBindTexture(GL_TEXTURE_2D, shadowTex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, shadowSize, shadowSize, 0,
               GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const GLfloat border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  glGenFramebuffers(1, &shadowFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadowTex, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  checkFramebuffer("shadow map");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void OsmesaRenderer::Impl::uploadTexture(const ImageRGBA8& tex, bool ruled) {
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, paperTex);
  if (ruled ? textureIsRuled
            : (!textureIsRuled && uploadedTexture.width == tex.width &&
               uploadedTexture.height == tex.height && uploadedTexture.pixels == tex.pixels))
    return;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8_ALPHA8, tex.width, tex.height, 0, GL_RGBA,
               GL_UNSIGNED_BYTE, tex.pixels.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  textureIsRuled = ruled;
  // Bilinear alpha is below 0.5 somewhere only if some texel's is.
  textureHasCut = false;
  for (std::size_t i = 3; i < tex.pixels.size(); i += 4)
    if (tex.pixels[i] < 128) {
      textureHasCut = true;
      break;
    }
  if (ruled)
    uploadedTexture = ImageRGBA8();
  else
    uploadedTexture = tex;
}

void OsmesaRenderer::Impl::uploadMask(const mesh::TearAtlas& atlas) {
  glActiveTexture(GL_TEXTURE0 + kMaskUnit);
  glBindTexture(GL_TEXTURE_2D, maskTex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, atlas.width, atlas.height, 0, GL_RED, GL_UNSIGNED_BYTE,
               atlas.mask.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace crumple::render
