// Separable Gaussian blur of an ESM atlas in log space: the blurred occluder
// depth is z0 + log(sum w_i exp(c (z_i - z0))) / c with z0 the largest tap, so
// no exponent exceeds 0 and c can be large. Taps stay inside their tile.
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;
uniform vec2 direction = vec2(1.0, 0.0); // in texels
uniform int radius = 2;
uniform float c = 90.0;
uniform float tile = 512.0;

out float blurred;

void main() {
  ivec2 size = textureSize(src, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 lo = ivec2(floor(vec2(p) / tile) * tile);
  ivec2 hi = min(lo + ivec2(tile) - 1, size - 1);
  int r = clamp(radius, 0, 32);
  float sigma = max(float(r) * 0.5, 0.5);
  float z0 = 0.0;
  for (int i = -r; i <= r; i++)
    z0 = max(z0, texelFetch(src, clamp(p + ivec2(direction) * i, lo, hi), 0).r);
  float k = max(c, 1e-3), sum = 0.0;
  for (int i = -r; i <= r; i++) {
    float z = texelFetch(src, clamp(p + ivec2(direction) * i, lo, hi), 0).r;
    sum += exp(-0.5 * float(i * i) / (sigma * sigma)) * exp(k * (z - z0));
  }
  float norm = 0.0;
  for (int i = -r; i <= r; i++) norm += exp(-0.5 * float(i * i) / (sigma * sigma));
  // sum includes z0's own tap, so sum / norm > 0 and the log is finite.
  blurred = z0 + log(max(sum / norm, 1e-30)) / k;
}
