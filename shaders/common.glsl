// Engine data every shader may read, and guarded math helpers.
#ifndef LIMN_COMMON_GLSL
#define LIMN_COMMON_GLSL

layout(std140, binding = 0) uniform LimnFrame {
  mat4 view, proj, view_proj, inv_view;
  vec4 camera_pos;
  vec4 frustum_o, frustum_u, frustum_v; // rays from the eye to the far plane
  vec4 clip;        // near, far, 1/far, tan(fov_y / 2)
  vec4 output_size; // w, h, 1/w, 1/h
  vec4 time;        // seconds, frame index
  ivec4 counts;     // x: lights
  mat4 prev_view_proj; // last frame's, for reprojection and motion blur
  vec4 exposure;    // x: the pre-exposure E, y: 1/E, z: E over the last frame's (see exposed()),
                    // w: the exposure meter's last key times E (> 0; 1: none metered)
} frame;

struct Light {
  vec4 position;  // xyz, w: 0 point, 1 spot, 2 directional
  vec4 direction; // xyz unit (from the light), w: cos(outer cone)
  vec4 color;     // rgb * power, w: radius
  vec4 params;    // x: cos(inner cone), y: falloff (0 seed window, 1 none, 2 inverse square,
                  //    3 inverse square with KHR_lights_punctual's range window)
};
#ifdef LIGHT_BLOCKS
// A scene of at most LIGHT_BLOCKS lights (light_set(): a light-set variant in
// lighting.glsl, or its general loop) reads a uniform block's copy of them:
// llvmpipe reads a storage buffer lane by lane (LM_LIGHT_SET_VIEWS in
// engine/scene/scene.h says why).
layout(std140, binding = 1) uniform LimnLightSet { Light lights[LIGHT_BLOCKS]; };
#else
layout(std430, binding = 1) readonly buffer LimnLights { Light lights[]; };
#endif

// Light culling, built once a frame (engine/scene/lightgrid.c): the frustum in
// screen tiles and depth slices, each cluster listing the lights that may
// reach it. Read through lights_near() (lighting.glsl).
layout(std430, binding = 4) readonly buffer LimnLightGrid {
  ivec4 grid;        // tiles x, y, depth slices, tile side in pixels (0: every light everywhere)
  vec4 slicing;      // x: slices / log(far / near), y: near
  uvec4 grid_global; // x: lights of infinite reach, y: where their list starts in cells
  uint cells[];      // per cluster (offset, count) into cells, then the lists
};

// Pre-exposure: lighting passes work on radiance times the frame's exposure E
// (a power of two, engine/render's pre_exposure), so that half floats hold
// starlight and sunlight alike. The lights arrive times E; a shader that adds
// radiance of its own (ambient, background, sky, emission, thresholds in
// radiance) passes it through exposed(); the output stage divides E back
// out. A history kept from the last frame is times the last E: times
// frame.exposure.z it is in this frame's.
vec3 exposed(vec3 radiance) { return radiance * frame.exposure.x; }

const float PI = 3.14159265358979;
const float EPS = 1e-6;

float saturate(float x) { return clamp(x, 0.0, 1.0); }
vec3 saturate(vec3 x) { return clamp(x, 0.0, 1.0); }

// normalize() of a zero vector is NaN; this returns `fallback` instead.
vec3 safe_normalize(vec3 v, vec3 fallback) {
  float len2 = dot(v, v);
  return len2 > 1e-24 ? v * inversesqrt(len2) : fallback;
}

// Seed 000 eq 17.
float luminance(vec3 c) { return dot(c, vec3(0.27, 0.67, 0.06)); }

// The G-buffer's depth (gbuffer.dpt, std.frag): linear view depth / far as a
// 32-bit float, 0 where nothing was drawn. A float keeps 24 bits relative to
// its value at any magnitude, so the division costs one rounding at any
// near/far ratio (test_scale: 2e-7 at near 1e-5, far 1e6); visibility comes
// from reversed float depth (lm_scene_frame_data). Shaders encode and decode
// it through these and position_from_depth only.
float dpt_encode(float view_depth) { return max(view_depth, 0.0) * frame.clip.z; }
// The G-buffer's mat.a: coverage (>= 0.5: geometry), the material model and
// reflectivity r in [0, 1]: std (Phong) 1 - 0.22 r in [0.78, 1], pbr 0.74 -
// 0.22 r in [0.52, 0.74], apart from each other and from 0.5 in 8 bits.
float mat_alpha_encode(float reflectivity, bool pbr) {
  return (pbr ? 0.74 : 1.0) - 0.22 * clamp(reflectivity, 0.0, 1.0);
}
bool mat_alpha_pbr(float a) { return a >= 0.5 && a < 0.76; }
float mat_alpha_reflectivity(float a) {
  return a >= 0.5 ? clamp(((mat_alpha_pbr(a) ? 0.74 : 1.0) - a) / 0.22, 0.0, 1.0) : 0.0;
}
float dpt_view_depth(float dpt) { return max(dpt, 0.0) * frame.clip.y; }

// The texel of an image of `size`, `factor` times finer than a coarse one,
// that stands for coarse texel q: its block's centre, clamped to the image
// (a coarse pass reads the G-buffer there instead of an averaged copy).
ivec2 block_centre(ivec2 q, int factor, ivec2 size) { return clamp(q * factor + factor / 2, ivec2(0), size - 1); }

// The reach of a blur of `radius` for a pixel whose temporal history holds
// n frames (temporal.glsl's state .g): radius / n^narrow (temporal.narrow;
// blur.frag's AGE explains the choice): all of it for a new pixel, at the
// default 1/4 about 2/5 of it for a converged one of 36 frames.
// aged_radius: rounded to whole taps each side.
float aged_reach(int radius, float n, float narrow) { return float(radius) * pow(max(n, 1.0), -max(narrow, 0.0)); }
int aged_radius(int radius, float n, float narrow) { return int(round(aged_reach(radius, n, narrow))); }

// World position from dpt (linear depth / far) and the far-plane rays (seed 000, eq 23-24).
vec3 position_from_depth(vec2 uv, float depth01) {
  vec3 ray = frame.frustum_o.xyz + frame.frustum_u.xyz * uv.x + frame.frustum_v.xyz * uv.y;
  return frame.camera_pos.xyz + ray * depth01;
}

// The octahedral coordinates (-1..1 each) of direction n (any length; zero
// gives +z): oct_decode's inverse.
vec2 oct_encode(vec3 n) {
  vec2 o = n.xy / max(abs(n.x) + abs(n.y) + abs(n.z), 1e-30);
  if (n.z < 0.0) o = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);
  return o;
}

// A unit normal as one float, held exactly: octahedral coordinates of 12
// bits each make an integer below 2^24, which a float holds exactly, stored
// as -1 - that integer so that a value above 0 can mean "none" (the RSM's
// position target carries its texel's normal in w this way: one fetch for
// both). normal_unpack(normal_pack(n)) is within 0.05 degrees of n.
float normal_pack(vec3 n) {
  uvec2 q = uvec2(round(clamp(oct_encode(n) * 0.5 + 0.5, 0.0, 1.0) * 4095.0));
  return -1.0 - float(q.x * 4096u + q.y);
}
// oct_decode: the unit vector at octahedral coordinates o (-1..1 each): a
// mesh's normals (vertex attribute 1, lm_mesh) and normal_pack's;
// oct_direction: the same direction before normalizing (|x| + |y| + |z| = 1,
// never zero): enough for the sign of a dot product.
vec3 oct_direction(vec2 o) {
  vec3 n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
  if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return n;
}
vec3 oct_decode(vec2 o) { return safe_normalize(oct_direction(o), vec3(0.0, 0.0, 1.0)); }
// normal_unpack_direction: normal_unpack before normalizing (oct_direction's).
vec3 normal_unpack_direction(float w) {
  uint c = uint(clamp(-1.0 - w, 0.0, 16777215.0));
  return oct_direction(vec2(uvec2(c >> 12, c & 4095u)) / 4095.0 * 2.0 - 1.0);
}
vec3 normal_unpack(float w) { return safe_normalize(normal_unpack_direction(w), vec3(0.0, 0.0, 1.0)); }

// The G-buffer's normal target (gbuffer.nrm and ISR's coarse copy, rgba8:
// std.frag and pbr.frag write it, gbuffer_normal_decode reads it): 4 bytes
// a pixel where half floats took 8, which llvmpipe writes and reads in less
// time (docs/benchmarks.md). rgb: the octahedral coordinates of the unit
// normal at 12 bits each, 2048 + 2047 o, so that o = 0 and +-1 are exact (an
// axis-aligned normal, +-z included, comes back bit for bit; any other
// within 0.07 degrees, where half floats kept 0.021); a: log2(1 + shininess)
// in 16ths, exact at 0 and 1, within 2.2% of 1 + shininess elsewhere, up to
// 62700. A texel of zeros (nothing drawn) decodes as (0, 1, 0), shininess 0.
vec4 gbuffer_normal_encode(vec3 n, float shininess) {
  uvec2 q = uvec2(round(clamp(oct_encode(n), -1.0, 1.0) * 2047.0) + 2048.0); // 1 .. 4095
  uvec3 b = uvec3(q.x >> 4, ((q.x & 15u) << 4) | (q.y >> 8), q.y & 255u);
  float a = round(clamp(log2(1.0 + max(shininess, 0.0)) * 16.0, 0.0, 255.0));
  return vec4(vec3(b), a) / 255.0;
}
vec4 gbuffer_normal_decode(vec4 t) {
  uvec4 b = uvec4(round(clamp(t, 0.0, 1.0) * 255.0));
  uvec2 q = uvec2((b.x << 4) | (b.y >> 4), ((b.y & 15u) << 8) | b.z);
  vec3 n = q.x == 0u ? vec3(0.0, 1.0, 0.0) : oct_decode((vec2(q) - 2048.0) / 2047.0);
  return vec4(n, exp2(float(b.w) / 16.0) - 1.0);
}

// Replaces NaN and Inf by zero, negatives by zero.
vec3 finite_or_zero(vec3 c) {
  bvec3 bad = bvec3(isnan(c.x) || isinf(c.x), isnan(c.y) || isinf(c.y), isnan(c.z) || isinf(c.z));
  return max(mix(c, vec3(0.0), bad), vec3(0.0));
}
vec4 finite_or_zero(vec4 c) {
  bool bad = isnan(c.w) || isinf(c.w);
  return vec4(finite_or_zero(c.xyz), bad ? 0.0 : max(c.w, 0.0));
}

// Linear [0, 1] to sRGB's encoding (IEC 61966-2-1): 12.92 c below 0.0031308,
// else 1.055 c^(1/2.4) - 0.055, that part as a degree-5 polynomial in
// c^(1/8) (three square roots), fitted over [0.0031308, 1] by least squares
// at Chebyshev nodes: within 3.2e-5 of 1/255 of the formula, so an 8-bit
// value differs from the formula's in 2 of 100000 (rounding ties). On
// llvmpipe pow() is a log2 and an exp2 polynomial a lane: a pass that reads
// and encodes took 2.0 and 3.0 times a plain copy's time with it, 1.4 and
// 1.5 with this (two runs in one process, 512x384; a third at load 7 told
// them apart no more).
vec3 srgb_encode(vec3 c) {
  c = saturate(c);
  vec3 y = sqrt(sqrt(sqrt(c)));
  vec3 hi = -0.0582374433 + y * (0.0330619859 + y * (-0.163281445 + y * (0.909687691 + y * (0.312755934 +
            y * -0.033986832))));
  return mix(c * 12.92, hi, step(vec3(0.0031308), c));
}

// glTF alphaMode MASK (a material variant's ALPHA_MASK, lm_scene_draw): a
// fragment whose alpha, material_alpha.x times the base colour texel's, is
// below the cutoff material_alpha.y is no surface, in the G-buffer and in
// shadow maps alike.
#ifdef ALPHA_MASK
uniform vec2 material_alpha;
bool alpha_masked(float texel_alpha) { return material_alpha.x * texel_alpha < material_alpha.y; }
#endif

#endif
