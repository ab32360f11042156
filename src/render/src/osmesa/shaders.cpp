// The rasteriser's GLSL 330 shaders and their compilation.
#include "shaders.hpp"

#include <algorithm>
#include <stdexcept>

namespace crumple::render::gl {

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

namespace {

// Compiles one shader after "#version 330 core" and `defines`.
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

}  // namespace

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

}  // namespace crumple::render::gl
