// Separable Gaussian blur of an ESM atlas in log space: the blurred occluder
// depth is z0 + log(sum w_i exp(k (z_i - z0))) / k with z0 the largest tap, so
// no exponent exceeds 0 and k can be large. k is the lookup's (shadow.glsl):
// c per texel of depth, from the tile's view. Taps stay inside their tile.
#include "shadow.glsl"

in vec2 uv;
uniform vec2 direction = vec2(1.0, 0.0); // in texels
uniform int radius = 2;
uniform float c = 16.0;
uniform float tile = 512.0;
uniform int views = 1 << 30; // tiles in use, row by row; the grid's spare cells stay clear

out float blurred;

void main() {
  ivec2 size = textureSize(shadow_atlas, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 cell = ivec2(vec2(p) / tile);
  int view = cell.x + cell.y * int(float(size.x) / tile);
  if (view >= views) {
    blurred = 1.0; // no tile here: what the shadow pass clears to
    return;
  }
  ivec2 lo = ivec2(floor(vec2(p) / tile) * tile);
  ivec2 hi = min(lo + ivec2(tile) - 1, size - 1);
  int r = clamp(radius, 0, 32);
  float inv_two_sigma2 = 1.0 / (2.0 * max(float(r) * 0.5, 0.5) * max(float(r) * 0.5, 0.5));
  // One pass of a running log-sum-exp: z0 is the largest depth so far and
  // sum is scaled to it, so no exponent is ever positive.
  float z0 = texelFetch(shadow_atlas, p, 0).r, sum = 0.0, norm = 0.0;
  float k = max(c, 1e-3) / shadow_texel_depth(shadow_views[view], z0);
  for (int i = -r; i <= r; i++) {
    float w = exp(-float(i * i) * inv_two_sigma2);
    float z = shadow_texel(p + ivec2(direction) * i, lo, hi);
    if (z > z0) {
      sum *= exp(k * (z0 - z));
      z0 = z;
    }
    sum += w * exp(k * (z - z0));
    norm += w;
  }
  // sum holds at least the largest tap's own weight, so the log is finite.
  blurred = z0 + log(max(sum / norm, 1e-30)) / k;
}
