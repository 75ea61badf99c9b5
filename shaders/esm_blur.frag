// Separable Gaussian blur of an ESM atlas in log space: the blurred occluder
// depth is z0 + log(sum w_i exp(k (z_i - z0))) / k with z0 the largest tap, so
// no exponent exceeds 0 and k can be large. k is the lookup's (shadow.glsl):
// c per texel of depth, from the tile's view. Taps stay inside their tile.
// Over depths (the map negates faces the light sees from behind, shadow.frag):
// the result keeps its own texel's sign.
#include "shadow.glsl"

in vec2 uv;
uniform vec2 direction = vec2(1.0, 0.0); // in texels
uniform int radius = 2;
uniform float c = 16.0;
uniform int views = 1 << 30; // the shadow tiles, the first views; texels of no tile stay clear

out float blurred;

void main() {
  ivec2 size = textureSize(shadow_atlas, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  // The tile holding p: tiles differ in size (a local light's are as fine as
  // the screen needs, engine/shadow), so each texel looks its tile up among
  // the views, a loop the default (no blur) never runs.
  int view = -1;
  ivec2 lo, hi;
  for (int v = 0; v < min(views, shadow_views.length()) && view < 0; v++) {
    vec4 rect = shadow_views[v].rect;
    lo = ivec2(floor(rect.xy * vec2(size) + 0.5));
    hi = lo + ivec2(floor(rect.zw * vec2(size) + 0.5)) - 1;
    if (all(greaterThanEqual(p, lo)) && all(lessThanEqual(p, hi))) view = v;
  }
  if (view < 0) {
    blurred = 1.0; // no tile here: what the shadow pass clears to
    return;
  }
  int r = clamp(radius, 0, 32);
  float inv_two_sigma2 = 1.0 / (2.0 * max(float(r) * 0.5, 0.5) * max(float(r) * 0.5, 0.5));
  // One pass of a running log-sum-exp: z0 is the largest depth so far and
  // sum is scaled to it, so no exponent is ever positive.
  float own = texelFetch(shadow_atlas, p, 0).r, z0 = abs(own), sum = 0.0, norm = 0.0;
  float k = max(c, 1e-3) / shadow_texel_depth(shadow_views[view], z0);
  for (int i = -r; i <= r; i++) {
    float w = exp(-float(i * i) * inv_two_sigma2);
    float z = abs(shadow_texel(p + ivec2(direction) * i, lo, hi));
    if (z > z0) {
      sum *= exp(k * (z0 - z));
      z0 = z;
    }
    sum += w * exp(k * (z - z0));
    norm += w;
  }
  // sum holds at least the largest tap's own weight, so the log is finite.
  float d = z0 + log(max(sum / norm, 1e-30)) / k;
  blurred = own >= 0.0 ? d : -max(d, 1e-30);
}
