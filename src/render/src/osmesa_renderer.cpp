// The OSMesa preview rasteriser (llvmpipe, GL 3.3 core, GLSL 330).
//
// Passes per frame: (1) a depth-only shadow map of the paper seen from the key
// light (the first light with shadow == true); (2) ground and paper into a 4x
// multisampled framebuffer, two-sided Lambert shading with PCF shadows, sRGB
// encoded in the shader; (2b) when a structure overlay is given, its lines
// (depth-tested) and points (on top) as flat screen-space triangles into the
// same framebuffer; (3) resolve, read back, flip to top-down rows and turn the
// coverage-weighted colours into straight alpha.
//
// Link OSMesa only: with libGL linked too every GL call is a no-op.
#define GL_GLEXT_PROTOTYPES 1
// clang-format off
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
// clang-format on

#include "crumple/render/osmesa_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>

#include "structure_overlay.hpp"

namespace crumple::render {

namespace {

constexpr int kMaxLights = 16;
// Shadow map side: the map is fitted to the casters, so 1024 texels give
// ~0.3 mm on an A4 sheet, finer than a pixel of a 1280 x 720 frame showing the
// sheet; images over 2048 pixels wide get 2048 (a 2048 map costs ~10 ms).
constexpr int kShadowMapSmall = 1024;
constexpr int kShadowMapLarge = 2048;
constexpr int kMaxSamples = 4;

// llvmpipe compiles shaders for the CPU it runs on; AVX, FMA and the vector
// width change floating-point results in the last bit. Pinning the feature set
// to SSE4.1 (no FMA, 128-bit vectors) makes images byte-identical across x86-64
// machines of the same Mesa/LLVM build. Mesa reads the variable once, when the
// first context of the process is created; a value the user set is kept.
void pinLlvmpipeCpuFeatures() {
  static std::once_flag once;
  std::call_once(once, [] { ::setenv("GALLIUM_OVERRIDE_CPU_CAPS", "sse4.1", 0); });
}

// --- shaders ----------------------------------------------------------------

const char* const kMainVertex = R"(
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
#ifdef TEAR_MASK
layout(location = 3) in vec2 a_maskUv;
out vec2 v_maskUv;
#endif
uniform mat4 u_viewProj;
out vec3 v_pos;
out vec3 v_normal;
out vec2 v_uv;
void main() {
  v_pos = a_pos;
  v_normal = a_normal;
  v_uv = a_uv;
#ifdef TEAR_MASK
  v_maskUv = a_maskUv;
#endif
  gl_Position = u_viewProj * vec4(a_pos, 1.0);
}
)";

// Compiled per variant: NUM_LIGHTS (>= 1), KEY_LIGHT (index of the shadow
// casting light or -1), KEY_IS_POINT, IS_GROUND (a plain Lambert surface of
// colour u_groundColor: the ground and the props), TRI_COLORS (albedo per
// triangle from a buffer texture indexed by gl_PrimitiveID, the structure
// overlay's colours), ALPHA_CUT (the texture's alpha < 0.5 cuts the paper),
// TRANSMIT (the paper transmits u_transmittance of the light from its other
// side), ALBEDO (the albedo pass: unlit), and TEAR_MASK when defined (a tear
// patch: its mask < 0.5 cuts the paper too). llvmpipe executes both sides of
// a branch under a mask, so everything not needed is compiled out.
const char* const kMainFragment = R"(
in vec3 v_pos;
in vec3 v_normal;
in vec2 v_uv;
uniform sampler2D u_tex;
uniform sampler2DShadow u_shadowMap;
#if TRI_COLORS
uniform samplerBuffer u_triColors;
#endif
#ifdef TEAR_MASK
in vec2 v_maskUv;
uniform sampler2D u_mask;
#endif
uniform vec3 u_frontColor;
uniform vec3 u_backColor;
uniform float u_transmittance;
uniform vec4 u_lightAreaNormal[NUM_LIGHTS];  // w = 1: an area light emitting along xyz
uniform vec3 u_groundColor;
uniform vec3 u_ambient;
uniform vec3 u_cameraPos;
uniform vec4 u_lightVec[NUM_LIGHTS];       // w = 0: unit vector towards the light; w = 1: position
uniform vec3 u_lightRadiance[NUM_LIGHTS];  // colour * intensity
uniform mat4 u_lightViewProj;
uniform float u_shadowTexelWorld;  // world size of a shadow texel (per metre for point lights)
uniform float u_shadowTexel;       // 1 / shadow map size
out vec4 o_color;

vec3 encodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  vec3 lo = 12.92 * c;
  vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
  return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

#if KEY_LIGHT >= 0
// Fraction of the key light reaching p: a normal-offset lookup (slope scaled)
// and 2x2 taps of the bilinear depth comparison (a 3x3-texel tent filter);
// the shadow pass adds a slope-scaled polygon offset on top.
float keyVisibility(vec3 p, vec3 ng, vec3 L) {
  if (dot(ng, L) < 0.0) ng = -ng;
  float cosT = clamp(dot(ng, L), 0.0, 1.0);
  float sinT = sqrt(max(1.0 - cosT * cosT, 0.0));
  float texel = u_shadowTexelWorld;
#if KEY_IS_POINT
  texel *= length(u_lightVec[KEY_LIGHT].xyz - p);
#endif
  vec3 q = p + ng * (texel * (1.0 + 2.0 * sinT));
  vec4 lp = u_lightViewProj * vec4(q, 1.0);
  vec3 c = lp.xyz / lp.w * 0.5 + 0.5;
  float h = 0.5 * u_shadowTexel;
  float sum = textureLod(u_shadowMap, vec3(c.xy + vec2(-h, -h), c.z), 0.0) +
              textureLod(u_shadowMap, vec3(c.xy + vec2(h, -h), c.z), 0.0) +
              textureLod(u_shadowMap, vec3(c.xy + vec2(-h, h), c.z), 0.0) +
              textureLod(u_shadowMap, vec3(c.xy + vec2(h, h), c.z), 0.0);
  // Behind a point light or beyond the far plane: lit.
  return (lp.w <= 0.0 || c.z >= 1.0) ? 1.0 : 0.25 * sum;
}
#endif

void main() {
#if ALPHA_CUT && !IS_GROUND
  if (textureLod(u_tex, v_uv, 0.0).a < 0.5) discard;
#endif
#ifdef TEAR_MASK
  if (textureLod(u_mask, v_maskUv, 0.0).r < 0.5) discard;
#endif
  vec3 ng = cross(dFdx(v_pos), dFdy(v_pos));
  float ngLen = length(ng);
  ng = ngLen > 0.0 ? ng / ngLen : vec3(0.0, 1.0, 0.0);
  if (dot(ng, u_cameraPos - v_pos) < 0.0) ng = -ng;  // geometric normal facing the viewer

  // Shading normal: the smooth normal, flipped on the back side; the
  // geometric one where the smooth normals cancel (a flattened fold).
  float len = length(v_normal);
  vec3 n = len > 1e-4 ? (gl_FrontFacing ? v_normal : -v_normal) / len : ng;
#if IS_GROUND
  vec3 albedo = u_groundColor;
#elif TRI_COLORS
  vec3 albedo = texelFetch(u_triColors, gl_PrimitiveID).rgb;
#else
  vec3 albedo = (gl_FrontFacing ? u_frontColor : u_backColor) * texture(u_tex, v_uv).rgb;
#endif

#if ALBEDO
  o_color = vec4(encodeSrgb(albedo), 1.0);
#else
  vec3 light = u_ambient;
#if TRANSMIT && !IS_GROUND
  vec3 behind = vec3(0.0);
#endif
  for (int i = 0; i < NUM_LIGHTS; ++i) {
    vec4 lv = u_lightVec[i];
    vec3 d = lv.xyz - lv.w * v_pos;
    float d2 = max(dot(d, d), 1e-12);
    vec3 L = d * inversesqrt(d2);
    float atten = lv.w == 0.0 ? 1.0 : 1.0 / d2;
    vec4 an = u_lightAreaNormal[i];
    if (an.w > 0.0) atten *= max(dot(an.xyz, -L), 0.0);
    float vis = 1.0;
#if KEY_LIGHT >= 0
    if (i == KEY_LIGHT) vis = keyVisibility(v_pos, ng, L);
#endif
    float ndl = max(dot(n, L), 0.0);
    light += u_lightRadiance[i] * (ndl * atten * vis);
#if TRANSMIT && !IS_GROUND
    behind += u_lightRadiance[i] * (max(-dot(n, L), 0.0) * atten * vis);
#endif
  }
#if TRANSMIT && !IS_GROUND
  // Of the light on this side a (1 - T) is reflected; of the light on the
  // other side a T comes through; the ambient reaches both sides alike.
  light = u_ambient + (1.0 - u_transmittance) * (light - u_ambient) + u_transmittance * behind;
#endif
  o_color = vec4(encodeSrgb(albedo * light), 1.0);
#endif
}
)";

// The structure overlay: clip-space positions and sRGB colours computed on the
// CPU (structure_overlay.cpp), written unchanged.
const char* const kOverlayVertex = R"(
layout(location = 0) in vec4 a_clip;
layout(location = 1) in vec4 a_color;
flat out vec4 v_color;
void main() {
  v_color = a_color;
  gl_Position = a_clip;
}
)";

const char* const kOverlayFragment = R"(
flat in vec4 v_color;
out vec4 o_color;
void main() { o_color = v_color; }
)";

const char* const kShadowVertex = R"(
layout(location = 0) in vec3 a_pos;
layout(location = 2) in vec2 a_uv;
#ifdef TEAR_MASK
layout(location = 3) in vec2 a_maskUv;
out vec2 v_maskUv;
#endif
uniform mat4 u_lightViewProj;
out vec2 v_uv;
void main() {
  v_uv = a_uv;
#ifdef TEAR_MASK
  v_maskUv = a_maskUv;
#endif
  gl_Position = u_lightViewProj * vec4(a_pos, 1.0);
}
)";

// ALPHA_CUT: light passes where the paper is cut; TEAR_MASK (defined): and
// where a tear patch's mask cuts it.
const char* const kShadowFragment = R"(
in vec2 v_uv;
uniform sampler2D u_tex;
#ifdef TEAR_MASK
in vec2 v_maskUv;
uniform sampler2D u_mask;
#endif
void main() {
#if ALPHA_CUT
  if (textureLod(u_tex, v_uv, 0.0).a < 0.5) discard;
#endif
#ifdef TEAR_MASK
  if (textureLod(u_mask, v_maskUv, 0.0).r < 0.5) discard;
#endif
}
)";

GLuint compileShader(GLenum type, const std::string& defines, const char* body) {
  const std::string header = "#version 330 core\n" + defines;
  const char* sources[2] = {header.c_str(), body};
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 2, sources, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetShaderInfoLog(s, len, nullptr, log.data());
    throw std::runtime_error("OsmesaRenderer: shader compilation failed: " + log);
  }
  return s;
}

GLuint linkProgram(const std::string& defines, const char* vs, const char* fs) {
  const GLuint v = compileShader(GL_VERTEX_SHADER, defines, vs);
  const GLuint f = compileShader(GL_FRAGMENT_SHADER, defines, fs);
  const GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(p, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<std::size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(p, len, nullptr, log.data());
    throw std::runtime_error("OsmesaRenderer: shader link failed: " + log);
  }
  return p;
}

void checkFramebuffer(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error(std::string("OsmesaRenderer: incomplete ") + what +
                             " framebuffer (status " + std::to_string(status) + ")");
}

void checkGl(const char* where) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR)
    throw std::runtime_error(std::string("OsmesaRenderer: GL error ") + std::to_string(e) + " in " +
                             where);
}

// Column-major float copy of a double matrix for glUniformMatrix4fv.
std::array<float, 16> toGl(const Mat4& m) {
  std::array<float, 16> a{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      a[static_cast<std::size_t>(c * 4 + r)] = static_cast<float>(m(r, c));
  return a;
}

// Rotation whose local -Z is `forward` (a unit vector), local +Y roughly world +Y.
Mat3 frameLookingAlong(const Vec3& forward) {
  const Vec3 a = forward.cwiseAbs();
  const Vec3 up = (a.y() < 0.99) ? Vec3::UnitY() : Vec3::UnitZ();
  const Vec3 right = forward.cross(up).normalized();
  const Vec3 trueUp = right.cross(forward);
  Mat3 r;
  r.col(0) = right;
  r.col(1) = trueUp;
  r.col(2) = -forward;
  return r;
}

Mat4 viewFromFrame(const Mat3& r, const Vec3& eye) {
  Mat4 v = Mat4::Identity();
  v.topLeftCorner<3, 3>() = r.transpose();
  v.topRightCorner<3, 1>() = -(r.transpose() * eye);
  return v;
}

Mat4 orthographic(double l, double r, double b, double t, double n, double f) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2.0 / (r - l);
  m(1, 1) = 2.0 / (t - b);
  m(2, 2) = -2.0 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

Mat4 perspective(double halfAngle, double n, double f) {
  const double c = 1.0 / std::tan(halfAngle);
  Mat4 p = Mat4::Zero();
  p(0, 0) = c;
  p(1, 1) = c;
  p(2, 2) = (f + n) / (n - f);
  p(2, 3) = 2.0 * f * n / (n - f);
  p(3, 2) = -1.0;
  return p;
}

// Owns the OSMesa context; every GL object lives and dies with it.
class OsmesaContext {
 public:
  OsmesaContext() {
    // GL 3.3 core first, then a compatibility context of the same version.
    for (const int profile : {OSMESA_CORE_PROFILE, OSMESA_COMPAT_PROFILE}) {
      // clang-format off
      const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA,
                             OSMESA_DEPTH_BITS, 24,
                             OSMESA_STENCIL_BITS, 0,
                             OSMESA_ACCUM_BITS, 0,
                             OSMESA_PROFILE, profile,
                             OSMESA_CONTEXT_MAJOR_VERSION, 3,
                             OSMESA_CONTEXT_MINOR_VERSION, 3,
                             0};
      // clang-format on
      ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
      if (ctx_) break;
    }
    if (!ctx_) throw std::runtime_error("OsmesaRenderer: OSMesaCreateContextAttribs failed");
  }
  ~OsmesaContext() {
    if (ctx_) OSMesaDestroyContext(ctx_);
  }
  OsmesaContext(const OsmesaContext&) = delete;
  OsmesaContext& operator=(const OsmesaContext&) = delete;
  OSMesaContext get() const { return ctx_; }

 private:
  OSMesaContext ctx_ = nullptr;
};

struct Vertex {
  float pos[3];
  float normal[3];
  float uv[2];
};

// A corner of a tear patch's triangle: a Vertex and its atlas coordinates.
struct PatchVertex {
  float pos[3];
  float normal[3];
  float uv[2];
  float maskUv[2];  // normalised atlas coordinates
};

// The texture unit of the tear atlas's mask.
constexpr int kMaskUnit = 3;

}  // namespace

struct OsmesaRenderer::Impl {
  int width = 0;
  int height = 0;
  // Declared before the context so that it outlives it.
  std::vector<std::uint8_t> osmesaBuffer;
  OsmesaContext context;

  GLuint shadowProgram = 0;
  GLuint shadowCutProgram = 0;      // the shadow pass of a paper with cut-outs
  GLuint shadowMaskProgram = 0;     // ... of tear patches
  GLuint shadowMaskCutProgram = 0;  // ... of tear patches of a paper with cut-outs
  GLuint overlayProgram = 0;
  // Main-pass programs by variant (lights, key light, key is point, ground,
  // triangle colours, alpha cut, transmission, albedo pass, tear mask).
  std::map<std::array<int, 9>, GLuint> mainPrograms;
  int shadowSize = kShadowMapSmall;
  GLuint paperVao = 0, paperVbo = 0;
  GLuint groundVao = 0, groundVbo = 0;
  GLuint propVao = 0, propVbo = 0;
  GLuint patchVao = 0, patchVbo = 0;
  GLuint maskTex = 0;
  GLuint msFbo = 0, msColor = 0, msDepth = 0;
  GLuint resolveFbo = 0, resolveColor = 0;
  GLuint shadowFbo = 0, shadowTex = 0;
  GLuint paperTex = 0;
  GLuint overlayVao = 0, overlayVbo = 0;
  GLuint triColorBuffer = 0, triColorTex = 0;
  int samples = 0;

  // The texture currently uploaded (to skip re-uploading an unchanged one).
  bool textureIsRuled = false;
  bool textureHasCut = false;  // some texel's alpha < 0.5: the paper has cut-outs
  ImageRGBA8 uploadedTexture;

  std::vector<Vertex> vertices;            // three per sheet triangle (split shading normals)
  std::vector<PatchVertex> patchVertices;  // three per triangle of the tear patches
  std::vector<Vertex> propVertices;        // three per prop triangle, all props
  std::vector<GLint> propFirst;            // first vertex of each prop
  std::vector<std::uint8_t> readback;
  std::vector<GLfloat> triColors;

  Impl(int w, int h) : width(w), height(h), osmesaBuffer(static_cast<std::size_t>(w) * h * 4) {
    const Current current(*this);
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

  // Binds the context to the calling thread for one scope, then releases it,
  // so a renderer may be used from different threads one after the other.
  class Current {
   public:
    explicit Current(Impl& impl) {
      if (!OSMesaMakeCurrent(impl.context.get(), impl.osmesaBuffer.data(), GL_UNSIGNED_BYTE,
                             impl.width, impl.height))
        throw std::runtime_error("OsmesaRenderer: OSMesaMakeCurrent failed");
    }
    ~Current() { OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0); }
    Current(const Current&) = delete;
    Current& operator=(const Current&) = delete;
  };

  void createPrograms() {
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

  GLuint mainProgram(int numLights, int keyLight, bool keyIsPoint, bool ground, bool triColors,
                     bool alphaCut, bool transmit, bool albedo, bool tearMask = false) {
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

  static void setupVertexLayout() {
    const auto stride = static_cast<GLsizei>(sizeof(Vertex));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offsetof(Vertex, pos)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offsetof(Vertex, normal)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offsetof(Vertex, uv)));
  }

  void createGeometry() {
    glGenVertexArrays(1, &paperVao);
    glGenBuffers(1, &paperVbo);
    glBindVertexArray(paperVao);
    glBindBuffer(GL_ARRAY_BUFFER, paperVbo);
    setupVertexLayout();

    glGenVertexArrays(1, &groundVao);
    glGenBuffers(1, &groundVbo);
    glBindVertexArray(groundVao);
    glBindBuffer(GL_ARRAY_BUFFER, groundVbo);
    setupVertexLayout();

    glGenVertexArrays(1, &propVao);
    glGenBuffers(1, &propVbo);
    glBindVertexArray(propVao);
    glBindBuffer(GL_ARRAY_BUFFER, propVbo);
    setupVertexLayout();

    glGenVertexArrays(1, &patchVao);
    glGenBuffers(1, &patchVbo);
    glBindVertexArray(patchVao);
    glBindBuffer(GL_ARRAY_BUFFER, patchVbo);
    {
      const auto stride = static_cast<GLsizei>(sizeof(PatchVertex));
      glEnableVertexAttribArray(0);
      glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void*>(offsetof(PatchVertex, pos)));
      glEnableVertexAttribArray(1);
      glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void*>(offsetof(PatchVertex, normal)));
      glEnableVertexAttribArray(2);
      glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void*>(offsetof(PatchVertex, uv)));
      glEnableVertexAttribArray(3);
      glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, stride,
                            reinterpret_cast<const void*>(offsetof(PatchVertex, maskUv)));
    }

    glGenVertexArrays(1, &overlayVao);
    glGenBuffers(1, &overlayVbo);
    glBindVertexArray(overlayVao);
    glBindBuffer(GL_ARRAY_BUFFER, overlayVbo);
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

  // Per-triangle albedo (linear RGB) as an RGBA32F buffer texture on unit 2.
  void uploadTriangleColors(const std::vector<Vec3>& colors) {
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

  // Lines depth-tested against the paper, the ground and each other, then
  // points over everything (already sorted far to near).
  void drawOverlay(const detail::OverlayGeometry& g) {
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

  void createTargets() {
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

  void uploadTexture(const ImageRGBA8& tex, bool ruled) {
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

  // The tear atlas's mask as a single-channel texture on kMaskUnit (GL_LINEAR,
  // clamped, level 0 only: mesh::sampleTearMask's lookup).
  void uploadMask(const mesh::TearAtlas& atlas) {
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

  ImageRGBA8 render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const StructureOverlay* overlay, RenderPass pass);
};

namespace {

// The preview's own checks on top of validateRenderInput.
void validateInput(const RenderScene& scene, const mesh::SheetMesh& sheet, int width, int height) {
  const Camera& cam = scene.camera;
  if (cam.width != width || cam.height != height)
    throw std::invalid_argument("OsmesaRenderer: camera is " + std::to_string(cam.width) + "x" +
                                std::to_string(cam.height) + " but the renderer is " +
                                std::to_string(width) + "x" + std::to_string(height));
  if (static_cast<int>(scene.lights.size()) > kMaxLights)
    throw std::invalid_argument("OsmesaRenderer: at most " + std::to_string(kMaxLights) +
                                " lights");
  validateRenderInput(scene, sheet, "OsmesaRenderer");
}

}  // namespace

ImageRGBA8 OsmesaRenderer::Impl::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                        const StructureOverlay* overlay, RenderPass pass) {
  validateInput(scene, sheet, width, height);
  if (overlay != nullptr) {
    detail::validateOverlay(*overlay, sheet.triangles.size());
    if (overlay->empty()) overlay = nullptr;  // the same bytes as no overlay
  }
  const Current current(*this);

  // Everything is drawn relative to the paper's bounding-box centre so that the
  // float vertex positions keep their precision wherever the sheet is.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : sheet.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const bool hasPaper = !sheet.triangles.empty();
  const Vec3 origin = sheet.positions.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));

  // Three vertices per triangle: the shading normals are split across
  // creases and around sharp vertices (shadingNormals).
  const auto cornerNormals = shadingNormals(sheet.positions, sheet.triangles,
                                            scene.paper.creaseAngle, scene.sharpVertices);
  const std::size_t nt = sheet.triangles.size();
  // Tear patches are drawn instead of their triangles (view.hpp), except in
  // the structure view with triangle colours, which shows the mesh.
  const bool torn =
      !scene.tears.empty() && !(overlay != nullptr && !overlay->triangleColors.empty());
  std::vector<char> replaced(nt, 0);
  if (torn)
    for (const mesh::TearPatch& p : scene.tears.patches)
      replaced[static_cast<std::size_t>(p.triangle)] = 1;
  vertices.clear();
  vertices.reserve(nt * 3);
  const Vec2& ts = scene.paper.textureSize;
  // Fills the attributes a sheet vertex and a patch vertex share.
  const auto setVertex = [&](auto& v, const Vec3& position, const Vec3& n, const Vec2& pattern) {
    const Vec3 p = position - origin;
    // The texture's top row sits at pattern y = textureSize.y: seen from the
    // front with the pattern's +y up, the image is upright and not mirrored.
    const Vec2 uv = patternToUv(pattern, ts);
    for (int c = 0; c < 3; ++c) {
      v.pos[c] = static_cast<float>(p[c]);
      v.normal[c] = static_cast<float>(n[c]);
    }
    v.uv[0] = static_cast<float>(uv.x());
    v.uv[1] = static_cast<float>(uv.y());
  };
  for (std::size_t t = 0; t < nt; ++t) {
    if (replaced[t]) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto i = static_cast<std::size_t>(sheet.triangles[t][k]);
      setVertex(vertices.emplace_back(), sheet.positions[i], cornerNormals[t][k], sheet.pattern[i]);
    }
  }
  glBindVertexArray(paperVao);
  glBindBuffer(GL_ARRAY_BUFFER, paperVbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)),
               vertices.data(), GL_STREAM_DRAW);
  // The tear patches (thesis 3.3.4, Fig. 3.25): the triangle and its
  // support quads, cut by the patch's mask.
  patchVertices.clear();
  if (torn) {
    const Vec2 atlasSize(scene.tears.width, scene.tears.height);
    for (const mesh::TearPatch& patch : scene.tears.patches) {
      const auto t = static_cast<std::size_t>(patch.triangle);
      for (const mesh::TearPatchTriangle& piece : mesh::tearPatchTriangles(patch, sheet))
        for (const mesh::TearPatchVertex& pv : piece) {
          PatchVertex& v = patchVertices.emplace_back();
          setVertex(v, pv.position, cornerNormals[t][static_cast<std::size_t>(pv.corner)],
                    pv.pattern);
          const Vec2 m =
              mesh::atlasPosition(scene.tears, patch, pv.pattern).cwiseQuotient(atlasSize);
          v.maskUv[0] = static_cast<float>(m.x());
          v.maskUv[1] = static_cast<float>(m.y());
        }
    }
    glBindVertexArray(patchVao);
    glBindBuffer(GL_ARRAY_BUFFER, patchVbo);
    glBufferData(GL_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(patchVertices.size() * sizeof(PatchVertex)),
                 patchVertices.data(), GL_STREAM_DRAW);
    uploadMask(scene.tears);
  }

  // Props: flat-shaded, three vertices per triangle, one draw each.
  propVertices.clear();
  propFirst.clear();
  for (const PropMesh& prop : scene.props) {
    propFirst.push_back(static_cast<GLint>(propVertices.size()));
    for (const auto& t : prop.triangles) {
      const Vec3 a = prop.vertices[static_cast<std::size_t>(t[0])] - origin;
      const Vec3 b = prop.vertices[static_cast<std::size_t>(t[1])] - origin;
      const Vec3 c = prop.vertices[static_cast<std::size_t>(t[2])] - origin;
      const Vec3 fn = (b - a).cross(c - a);
      const Vec3 n = fn.norm() > 0.0 ? Vec3(fn.normalized()) : Vec3::Zero();
      for (const Vec3* q : {&a, &b, &c}) {
        Vertex v{};
        for (int k = 0; k < 3; ++k) {
          v.pos[k] = static_cast<float>((*q)[k]);
          v.normal[k] = static_cast<float>(n[k]);
        }
        propVertices.push_back(v);
      }
    }
  }
  propFirst.push_back(static_cast<GLint>(propVertices.size()));
  if (!propVertices.empty()) {
    glBindVertexArray(propVao);
    glBindBuffer(GL_ARRAY_BUFFER, propVbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(propVertices.size() * sizeof(Vertex)),
                 propVertices.data(), GL_STREAM_DRAW);
  }

  // Ground: a square at Y = height centred under the paper's bounding box,
  // counter-clockwise seen from above (front face up).
  std::array<Vec3, 4> groundCorners{};
  if (scene.ground.enabled) {
    const double h = 0.5 * scene.ground.size;
    const double y = scene.ground.height - origin.y();
    groundCorners = {Vec3(-h, y, h), Vec3(h, y, h), Vec3(h, y, -h), Vec3(-h, y, -h)};
    std::array<Vertex, 6> quad{};
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; ++i) {
      const Vec3& c = groundCorners[static_cast<std::size_t>(order[i])];
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

  // Lights. An empty list gets one default directional light without shadow.
  std::vector<Light> lights = scene.lights;
  if (lights.empty()) lights.push_back(Light{});
  int key = -1;
  for (std::size_t i = 0; i < lights.size(); ++i)
    if (lights[i].shadow) {
      key = static_cast<int>(i);
      break;
    }

  // The paper texture (unit 0), needed by the shadow pass of a cut paper.
  if (scene.paper.texture.pixels.empty())
    uploadTexture(defaultPaperTexture(), true);
  else
    uploadTexture(scene.paper.texture, false);
  const bool alphaCut = textureHasCut;

  // --- shadow pass ------------------------------------------------------------
  Mat4 lightViewProj = Mat4::Identity();
  double shadowTexelWorld = 0.0;
  const bool shadows = key >= 0 && hasPaper;
  if (shadows) {
    const Light& kl = lights[static_cast<std::size_t>(key)];
    // Casters: the paper and the props; receivers: those and the ground.
    std::vector<Vec3> receivers;
    for (const Vec3& p : sheet.positions) {
      const Vec3 q = p - origin;
      receivers.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                             static_cast<float>(q.z()));
    }
    for (const Vertex& v : propVertices) receivers.emplace_back(v.pos[0], v.pos[1], v.pos[2]);
    for (const PatchVertex& v : patchVertices) receivers.emplace_back(v.pos[0], v.pos[1], v.pos[2]);
    const std::size_t nv = receivers.size();
    if (scene.ground.enabled)
      for (const Vec3& c : groundCorners) receivers.push_back(c);
    if (kl.kind == Light::Kind::Directional) {
      // Orthographic, fitted in x/y to the paper (nothing outside it can be
      // shadowed) and in depth to the paper and the ground.
      const Mat3 r = frameLookingAlong(kl.direction.normalized());
      const Mat4 view = viewFromFrame(r, Vec3::Zero());
      Vec3 lmin = Vec3::Constant(std::numeric_limits<double>::infinity()), lmax = -lmin;
      for (std::size_t i = 0; i < nv; ++i) {
        const Vec3 q = (view * receivers[i].homogeneous()).head<3>();
        lmin = lmin.cwiseMin(q);
        lmax = lmax.cwiseMax(q);
      }
      double zmin = lmin.z(), zmax = lmax.z();
      for (const Vec3& p : receivers) {
        const double z = (view * p.homogeneous()).z();
        zmin = std::min(zmin, z);
        zmax = std::max(zmax, z);
      }
      const double extent = std::max({lmax.x() - lmin.x(), lmax.y() - lmin.y(), 1e-6});
      const double pad = 0.02 * extent + 4.0 * extent / shadowSize;
      const double depthPad = 0.01 * std::max(zmax - zmin, 1e-3);
      const Mat4 proj = orthographic(lmin.x() - pad, lmax.x() + pad, lmin.y() - pad, lmax.y() + pad,
                                     -zmax - depthPad, -zmin + depthPad);
      lightViewProj = proj * view;
      shadowTexelWorld = (extent + 2.0 * pad) / shadowSize;
    } else {
      // Perspective from the point (or area light's centre) towards the
      // casters' bounding sphere.
      const Vec3 eye = kl.position - origin;
      double radius = 0.0;
      for (std::size_t i = 0; i < nv; ++i) radius = std::max(radius, receivers[i].norm());
      radius = std::max(radius, 1e-6);
      const double dist = eye.norm();
      const Vec3 forward = dist > 0.0 ? Vec3(-eye / dist) : Vec3(-Vec3::UnitY());
      constexpr double kMaxHalfAngle = 75.0 * std::numbers::pi / 180.0;
      const double half =
          dist > 1.02 * radius
              ? std::min(kMaxHalfAngle, 1.02 * std::asin(radius / dist) + 4.0 / shadowSize)
              : kMaxHalfAngle;
      const double nearPlane = std::max(dist - radius, 1e-3 * radius) * 0.9;
      double farPlane = 2.0 * nearPlane;
      for (const Vec3& p : receivers) farPlane = std::max(farPlane, (p - eye).norm() * 1.01);
      lightViewProj =
          perspective(half, nearPlane, farPlane) * viewFromFrame(frameLookingAlong(forward), eye);
      shadowTexelWorld = 2.0 * std::tan(half) / shadowSize;
    }

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
    const auto lightMatrix = toGl(lightViewProj);
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
  }

  // --- main pass ----------------------------------------------------------------
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, shadowTex);
  glActiveTexture(GL_TEXTURE0);
  const bool triColors = overlay != nullptr && !overlay->triangleColors.empty() && hasPaper;
  if (triColors) uploadTriangleColors(overlay->triangleColors);

  Camera cam = scene.camera;
  cam.position -= origin;
  const Mat4 viewProj = projectionMatrix(cam) * viewMatrix(cam);

  glBindFramebuffer(GL_FRAMEBUFFER, msFbo);
  glViewport(0, 0, width, height);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  if (samples > 0) glEnable(GL_MULTISAMPLE);
  // Transparent black: the resolve then holds coverage-weighted colour and
  // coverage, turned into straight alpha below.
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  std::array<GLfloat, 4 * kMaxLights> lightVec{};
  std::array<GLfloat, 3 * kMaxLights> lightRad{};
  std::array<GLfloat, 4 * kMaxLights> lightAreaNormal{};
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    // Directional (and sun): unit vector towards the light (w = 0); point and
    // area: position (w = 1). An area light is a point light at its centre
    // whose intensity falls off with the cosine to its normal (view.hpp).
    Vec4 v;
    if (l.kind == Light::Kind::Directional)
      v << -l.direction.normalized(), 0.0;
    else
      v << l.position - origin, 1.0;
    const Vec3 rad = l.color * l.intensity;
    for (std::size_t k = 0; k < 4; ++k) lightVec[i * 4 + k] = static_cast<GLfloat>(v[k]);
    for (std::size_t k = 0; k < 3; ++k) lightRad[i * 3 + k] = static_cast<GLfloat>(rad[k]);
    if (l.kind == Light::Kind::Area) {
      const Vec3 n = l.direction.normalized();
      for (std::size_t k = 0; k < 3; ++k)
        lightAreaNormal[i * 4 + k] = static_cast<GLfloat>(n[static_cast<Eigen::Index>(k)]);
      lightAreaNormal[i * 4 + 3] = 1.0f;
    }
  }
  const auto numLights = static_cast<int>(lights.size());
  const int keyLight = shadows ? key : -1;
  const bool keyIsPoint =
      shadows && lights[static_cast<std::size_t>(key)].kind != Light::Kind::Directional;
  const bool albedoPass = pass == RenderPass::Albedo;
  const bool transmit = scene.paper.transmittance > 0.0;
  const auto vp = toGl(viewProj);
  const auto lvp = toGl(lightViewProj);

  // What: 0 the ground, 1 a prop (colour), 2 the paper, 3 the tear patches.
  auto draw = [&](int what, const Vec3& color, GLint first, GLsizei count) {
    const bool plain = what < 2;
    const GLuint program =
        mainProgram(numLights, keyLight, keyIsPoint, plain, triColors && !plain, alphaCut && !plain,
                    transmit && !plain, albedoPass, what == 3);
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
    set3("u_cameraPos", cam.position);
    glUniform1f(loc("u_transmittance"), static_cast<float>(scene.paper.transmittance));
    glUniform4fv(loc("u_lightVec"), numLights, lightVec.data());
    glUniform3fv(loc("u_lightRadiance"), numLights, lightRad.data());
    glUniform4fv(loc("u_lightAreaNormal"), numLights, lightAreaNormal.data());
    glUniform1f(loc("u_shadowTexelWorld"), static_cast<float>(shadowTexelWorld));
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
  if (hasPaper) draw(2, Vec3::Zero(), 0, static_cast<GLsizei>(vertices.size()));
  if (!patchVertices.empty()) draw(3, Vec3::Zero(), 0, static_cast<GLsizei>(patchVertices.size()));
  glBindVertexArray(0);
  if (overlay != nullptr)
    drawOverlay(detail::buildOverlayGeometry(*overlay, sheet, cam, viewProj, origin));

  // --- resolve and read back ----------------------------------------------------
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolveFbo);
  glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, resolveFbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  readback.resize(static_cast<std::size_t>(width) * height * 4);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, readback.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl("OsmesaRenderer::render");

  // GL rows are bottom-up; the image's are top-down. The resolved colour is
  // coverage-weighted (premultiplied): divide by coverage for straight alpha;
  // uncovered pixels carry the background colour with alpha 0.
  const std::array<std::uint8_t, 3> bg = {linearToSrgb8(scene.background.x()),
                                          linearToSrgb8(scene.background.y()),
                                          linearToSrgb8(scene.background.z())};
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

OsmesaRenderer::OsmesaRenderer(int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("OsmesaRenderer: width and height must be positive");
  pinLlvmpipeCpuFeatures();
  impl_ = std::make_unique<Impl>(width, height);
}

OsmesaRenderer::~OsmesaRenderer() = default;

ImageRGBA8 OsmesaRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                  const StructureOverlay* overlay, RenderPass pass) {
  return impl_->render(scene, sheet, overlay, pass);
}

}  // namespace crumple::render
