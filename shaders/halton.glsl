// Halton sampling for SSAO and SSDO (seed 001, lines 570-635, 776-829,
// 1235-1287), and the R3 sequence for ISR's march: three radical-inverse sequences, base 5 for the azimuth, base
// 2 for the elevation and base 3 for the step length along the direction.
// Bases 2 and 5 repeat their split of the hemisphere every 10 samples
// (seed lines 803-805), so the modules accept counts in multiples of 10 only
// (ssdo.lua and ssao.lua refuse others with an error naming the option; a
// shader handed one anyway rounds it down to a multiple of 10, at least 10).
//
// Where the sequence is made: here, in the shader. The seed kept it in a
// texture, one fetch per sample; a uniform array cannot be bound by a pass.
// Computing it costs base 2 one bitfieldReverse and bases 3 and 5 a loop of
// at most 6 integer divisions for i <= 300, against the sample's own depth,
// normal and colour fetches: cheaper than another fetch, no texture to
// build, and any count up to the limit without a table size to agree on.
//
// Against banding: every pixel sees the same directions, so the
// deterministic pattern shows as lines (seed line 956). Each pixel
// shifts the three coordinates by its own offset modulo 1 (a Cranley-
// Patterson rotation, which keeps the set's stratification) taken from its
// place in an interleaved T x T tile (T = `interleave`, 1, 2 or 4): the
// tile's T^2 pixels get T^2 different rotations, spread by a Bayer order so
// that neighbours differ most, and the geometry-aware blur (at least T wide)
// averages them back. T = 1 shows the raw pattern.
#ifndef LIMN_HALTON_GLSL
#define LIMN_HALTON_GLSL
#include "common.glsl"

const int HALTON_MAX = 300; // the most samples a pixel takes

// Phi_b(i) = sum_j a_j(i) b^(-j-1), seed eq 3.6.
float radical_inverse(uint i, uint base) {
  if (base == 2u) return float(bitfieldReverse(i)) * 2.3283064365386963e-10; // 2^-32
  float inv = 1.0 / float(base), f = inv, r = 0.0;
  for (int guard = 0; i > 0u && guard < 32; guard++) {
    r += f * float(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

// Index of pixel px within its interleaved tile of side t (1, 2 or 4), in
// Bayer order: 0 .. t*t - 1.
int interleave_index(ivec2 px, int t) {
  const int bayer4[16] = int[16](0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5);
  if (t >= 4) return bayer4[(px.y & 3) * 4 + (px.x & 3)];
  if (t == 2) return bayer4[(px.y & 1) * 4 + (px.x & 1)] / 4; // 0, 2, 3, 1
  return 0;
}

// The pixel's rotation: azimuth, elevation and step shifted by different
// low-discrepancy functions of its tile index, so the T^2 offsets fill the
// unit cube rather than a line.
vec3 halton_offset(ivec2 px, int t) {
  int n = t >= 4 ? 16 : (t == 2 ? 4 : 1);
  uint j = uint(interleave_index(px, t));
  return vec3((float(j) + 0.5) / float(n), fract(radical_inverse(j, 2u) + 0.5 / float(n)),
              radical_inverse(j, 3u));
}

// Sample i (0-based) of the pixel: (azimuth, elevation, step) in [0, 1)^3.
// The sequence starts at index 1: Phi_b(0) = 0 in every base.
vec3 halton_sample(int i, vec3 offset) {
  uint k = uint(i) + 1u;
  return fract(vec3(radical_inverse(k, 5u), radical_inverse(k, 2u), radical_inverse(k, 3u)) + offset);
}

// Point i (0-based) of Roberts' R3 sequence, shifted by offset modulo 1:
// fract((i + 1) alpha), alpha_d = phi^-d, phi = 1.2207440846 the root of
// x^4 = x + 1 (the generalized golden ratio), in 32-bit fixed point (exact
// modulo 1). As evenly spread as the Halton points for a pixel's few
// samples and any run of consecutive ones, at one integer multiply a
// coordinate instead of a loop of divisions a digit (isr_march.frag, whose
// 4 x 4 tiles take indices up to 16 times a pixel's samples: the Halton
// points cost a sixth of its time there).
vec3 r3_sample(int i, vec3 offset) {
  const uvec3 ALPHA = uvec3(3518319155u, 2882110345u, 2360945575u); // 2^32 phi^-d
  return fract(vec3(uint(i + 1) * ALPHA) * 2.3283064365386963e-10 + offset);
}

// Directions in the frame whose z is the normal (seed eq 5.2 and 5.3).
// Cosine-weighted, pdf cos(theta) / pi.
vec3 hemisphere_cosine(vec2 u) {
  float s = sqrt(max(1.0 - u.y, 0.0)), a = 2.0 * PI * u.x;
  return vec3(cos(a) * s, sin(a) * s, sqrt(max(u.y, 0.0)));
}
// Uniform in solid angle, pdf 1 / (2 pi).
vec3 hemisphere_uniform(vec2 u) {
  float s = sqrt(max(1.0 - u.y * u.y, 0.0)), a = 2.0 * PI * u.x;
  return vec3(cos(a) * s, sin(a) * s, u.y);
}

// An orthonormal frame around unit n (Duff et al. 2017: no division by a
// value that can be zero, no normalize).
mat3 tangent_frame(vec3 n) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z), b = n.x * n.y * a;
  vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
  return mat3(t, bt, n);
}
#endif
