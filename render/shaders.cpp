#include "render/shaders.hpp"

namespace wingman::render::shaders {

// What both colour programs' vertex shaders read, and the light besides the sun's beam on a face
// of world normal n: from u_bounce (facing down) to u_ambient (facing up); the two are equal under
// the constant sky (render/skylight.hpp).
const char* const kVertexInputs = R"(
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec3 a_colour;
uniform mat4 u_proj;
uniform mat3 u_model_rot;
uniform vec3 u_to_light;
uniform vec3 u_ambient;
uniform vec3 u_bounce;
uniform vec3 u_diffuse;
uniform bool u_unlit;
out vec2 v_uv;
vec3 sky(vec3 n) { return u_bounce + (u_ambient - u_bounce) * (0.5 + 0.5 * n.z); }
)";

// Lambert shading per vertex: the terrain's normals vary smoothly over its 2 m cells and the
// objects are flat-shaded, so per-pixel lighting changed nothing visible, while llvmpipe's
// fragment cost grows with every varying and instruction. The fragment shader is one texture
// lookup times one colour.
const char* const kSceneVs = R"(
out vec3 v_colour;
void main() {
  vec3 n = normalize(u_model_rot * a_normal);
  vec3 shade = u_unlit ? vec3(1.0) : sky(n) + u_diffuse * max(dot(n, u_to_light), 0.0);
  v_uv = a_uv;
  v_colour = a_colour * shade;
  gl_Position = u_proj * eye(a_pos);
}
)";

const char* const kSceneFs = R"(
in vec2 v_uv;
in vec3 v_colour;
layout(location = 0) out vec4 o_colour;
void main() {
  o_colour = vec4(surface(v_uv) * v_colour, 1.0);
}
)";

// The same with the sun's shadow (world.light.shadows): ambient and diffuse light kept apart per
// vertex, and the diffuse one scaled per pixel by what the shadow map lets through (2x2
// percentage-closer filtering by the sampler's compare mode). A program of its own, so that a
// world without shadows runs exactly the programs above.
const char* const kShadowedVs = R"(
uniform mat4 u_light_from_model;
uniform mat4 u_model;
uniform vec2 u_cloud_offset;  // m the clouds have drifted
uniform float u_cloud_period;  // m the cloud texture spans
uniform float u_cloud_height;
out vec3 v_ambient;
out vec3 v_direct;
out vec3 v_light;
#ifdef WINGMAN_CLOUDS
out vec2 v_cloud;
#endif
void main() {
#ifdef WINGMAN_CLOUDS
  // Where the ray to the sun crosses the cloud layer.
  vec3 p = (u_model * vec4(a_pos, 1.0)).xyz;
  v_cloud = (p.xy + u_to_light.xy * (u_cloud_height - p.z) / max(u_to_light.z, 0.05) - u_cloud_offset) / u_cloud_period;
#endif
  vec3 n = normalize(u_model_rot * a_normal);
  vec3 direct = u_unlit ? vec3(0.0) : u_diffuse * max(dot(n, u_to_light), 0.0);
  v_uv = a_uv;
  v_ambient = a_colour * (u_unlit ? vec3(1.0) : sky(n));
  v_direct = a_colour * direct;
  v_light = (u_light_from_model * vec4(a_pos, 1.0)).xyz;  // orthographic: w is 1
  gl_Position = u_proj * eye(a_pos);
}
)";

const char* const kShadowedFs = R"(
in vec2 v_uv;
in vec3 v_ambient;
in vec3 v_direct;
in vec3 v_light;
#ifdef WINGMAN_CLOUDS
in vec2 v_cloud;
#endif
uniform sampler2DShadow u_shadow;
uniform sampler2D u_clouds;
uniform bool u_zero_to_one;
uniform float u_cloud_block;  // 1 - the direct sun a cloud lets through; 0: no clouds
layout(location = 0) out vec4 o_colour;
void main() {
  vec3 p = v_light;
  float lit = texture(u_shadow, vec3(p.xy * 0.5 + 0.5, u_zero_to_one ? p.z : p.z * 0.5 + 0.5));
#ifdef WINGMAN_CLOUDS
  lit *= 1.0 - u_cloud_block * texture(u_clouds, v_cloud).r;
#endif
  o_colour = vec4(surface(v_uv) * (v_ambient + lit * v_direct), 1.0);
}
)";

// A surface's colour at texture coordinate uv: the texture as it is.
const char* const kImageLookup = R"(
uniform sampler2D u_tex;
vec3 surface(vec2 uv) { return texture(u_tex, uv).rgb; }
)";

// Stochastic tiling (world.texture.tiling; Heitz & Neyret 2018, in the form of Deliot & Heitz
// 2019): an equilateral triangle grid over the texture's plane; each grid vertex shows the piece
// of the image around its centre in u_pieces (render/piece_table.hpp: chosen so that nearby
// vertices never show copies of the same ground a short way apart, and at least a cell from the
// image's border so that no piece ever wraps over a seam); each pixel blends the three pieces of
// its triangle with sharpened barycentric weights, about the image's mean and divided by the
// weights' norm so that the blend keeps the image's variance. The gradients of the plain
// coordinate pick the mipmap level (each piece is the same coordinate shifted).
const char* const kStochasticLookup = R"(
#ifndef WINGMAN_GRADIENT_SCALE
#define WINGMAN_GRADIENT_SCALE 1.0  // the bake's is 0.5: the image's level 0, magnified
#endif
uniform sampler2D u_tex;
uniform float u_cell;         // grid side, in units of the texture's width
uniform float u_aspect;       // the texture's height over its width
uniform float u_sharpness;    // power of the blend weights
uniform vec3 u_mean;          // the image's mean colour
uniform sampler2D u_pieces;   // RG32F: each vertex's piece centre, periodic, a power of two wide
// The shift from the coordinate of vertex `id` to where its piece lies in the image.
vec2 piece_shift(ivec2 id) {
  vec2 centre = texelFetch(u_pieces, id & (textureSize(u_pieces, 0) - 1), 0).rg;
  vec2 at = u_cell * vec2(float(id.x) + 0.5 * float(id.y), 0.8660254 * float(id.y));
  return centre - at;
}
// The lattice's three-colouring: each triangle has one vertex of each colour.
int colour(ivec2 id) { return (id.x + 2 * id.y + 3000000) % 3; }
vec3 surface(vec2 uv) {
  vec2 dx = dFdx(uv) * WINGMAN_GRADIENT_SCALE, dy = dFdy(uv) * WINGMAN_GRADIENT_SCALE;
  vec2 q = vec2(uv.x, uv.y * u_aspect);
  vec2 g = mat2(1.0, 0.0, -0.57735027, 1.15470054) * (q / u_cell);
  ivec2 base = ivec2(floor(g));
  vec2 f = g - floor(g);
  float z = 1.0 - f.x - f.y;
  bool lower = z > 0.0;
  // The triangle's vertices and weights, each in the slot of its colour: across an edge the two
  // shared vertices keep their slots, so each lookup's coordinate jumps only where its weight is
  // nought (a 2x2 quad of pixels never filters one lookup from far-apart pieces).
  ivec2 id[3];
  vec3 w;
  ivec2 a = lower ? base : base + ivec2(1, 1), b = base + ivec2(1, 0), c = base + ivec2(0, 1);
  id[colour(a)] = a;
  id[colour(b)] = b;
  id[colour(c)] = c;
  w[colour(a)] = lower ? z : -z;
  w[colour(b)] = lower ? f.x : 1.0 - f.y;
  w[colour(c)] = lower ? f.y : 1.0 - f.x;
  w = pow(max(w, vec3(1e-4)), vec3(u_sharpness));  // pow(0, k) is undefined under fast math
  w /= w.x + w.y + w.z;
  // Each piece's shift in whole blocks of 8 texels: a texel of any of the image's first four
  // levels shows whole texels of its pieces at that level, so a bake of the tiling
  // (render/ground_bake.hpp) and its mipmaps hold what the live lookups sample, unresampled.
  vec2 size = vec2(textureSize(u_tex, 0)), s = vec2(1.0, 1.0 / u_aspect) * size / 8.0;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < 3; ++k)
    sum += w[k] * (textureGrad(u_tex, uv + 8.0 * round(piece_shift(id[k]) * s) / size, dx, dy).rgb - u_mean);
  return clamp(sum / sqrt(dot(w, w)) + u_mean, 0.0, 1.0);
}
)";

// With MSAA, depth comes from a second, single-sample pass of the same geometry with this
// program (no colour, no texture): the surface at the pixel centre, exactly as without MSAA, never
// a blend of two surfaces at an edge. Colour is resolved by glBlitFramebuffer. On llvmpipe this
// costs 12 ms less than one resolve shader averaging the colour samples and picking a depth.
const char* const kDepthInputs = R"(
layout(location = 0) in vec3 a_pos;
uniform mat4 u_proj;
)";

const char* const kDepthVs = R"(
void main() {
  gl_Position = u_proj * eye(a_pos);
}
)";

// A vertex's camera-frame position (every vertex shader's eye()): one model-view for the draw.
const char* const kOneViewEye = R"(
uniform mat4 u_model_view;
vec4 eye(vec3 p) { return u_model_view * vec4(p, 1.0); }
)";

// The same under a rolling shutter drawn in one pass (CameraView::rows): each knot's model-view
// is three texels of u_knots (row `u_group`: the static scene, the lead, each body); a vertex
// takes the model-view interpolated at the image row it lands on, found by fixed-point steps from
// the middle knot (each step moves the row by the image's speed across rows times the line delay,
// a small fraction of a pixel per pixel, so four steps leave no visible error). The row is the
// image's (lens distortion applied), not the canvas's a distorted camera is drawn on.
const char* const kRollingEye = R"(
uniform sampler2D u_knots;   // RGBA32F: knot k's model-view rows 0-2 at texels 3k .. 3k + 2
uniform int u_group;
uniform vec4 u_row_of;       // fy, cy, rows between knots, the last knot's index
uniform vec4 u_dist;         // k1, k2, p1, p2
uniform float u_k3;
vec4 at_knot(int k, vec4 p) {
  return vec4(dot(texelFetch(u_knots, ivec2(3 * k, u_group), 0), p),
              dot(texelFetch(u_knots, ivec2(3 * k + 1, u_group), 0), p),
              dot(texelFetch(u_knots, ivec2(3 * k + 2, u_group), 0), p), 1.0);
}
float image_row(vec4 e) {
  vec2 x = clamp(e.xy / max(e.z, 1e-4), vec2(-10.0), vec2(10.0));  // behind the camera: off the image
  float r2 = dot(x, x);
  float radial = 1.0 + r2 * (u_dist.x + r2 * (u_dist.y + r2 * u_k3));
  float y = x.y * radial + u_dist.z * (r2 + 2.0 * x.y * x.y) + 2.0 * u_dist.w * x.x * x.y;
  return u_row_of.x * y + u_row_of.y;
}
vec4 eye(vec3 pos) {
  vec4 p = vec4(pos, 1.0);
  float last = u_row_of.w, k = 0.5 * last;
  vec4 e;
  for (int i = 0; i < 4; ++i) {
    float kf = clamp(k, 0.0, last);
    int k0 = min(int(kf), int(last) - 1);
    e = mix(at_knot(k0, p), at_knot(k0 + 1, p), kf - float(k0));
    k = image_row(e) / u_row_of.z;
  }
  return e;
}
)";

const char* const kDepthFs = R"(
void main() {}
)";


const char* const kBakeVs = R"(
void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0);
}
)";

// Texel (i, j) is the surface at u_uv0 + (i + 0.5, j + 0.5) * u_texel, one image texel apart,
// read from the image's level 0 (the renderer compiles the lookup with half-texel gradients).
const char* const kBakeFs = R"(
uniform vec2 u_uv0;
uniform vec2 u_texel;
layout(location = 0) out vec4 o_colour;
void main() {
  o_colour = vec4(surface(u_uv0 + gl_FragCoord.xy * u_texel), 1.0);
}
)";

}  // namespace wingman::render::shaders
