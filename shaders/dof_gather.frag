// Depth of field, step 2: a gather that acts as a scatter. Each tap q of a
// disc of max_radius pixels (a Vogel spiral, `samples` taps) adds to this
// pixel p only if its own circle of confusion reaches p:
//   reach(q) = |coc_q|, but no more than |coc_p| when q lies behind p.
// So a blurred foreground spreads over a sharp background (its large circle
// reaches p whatever p's own), while a blurred background cannot bleed onto
// a sharp foreground, and a sharp foreground (circle ~0) reaches no blurred
// background pixel beside it. A tap stands for the disc area it samples
// (pi max_radius^2 / samples) and spreads its light over its own circle, so
// it weighs area / (pi coc_q^2), at most 1; p itself weighs 1 / (pi coc_p^2).
// A sharp pixel keeps its own light and a blurred foreground covers it in
// proportion to how much of its circle reaches it. Weights fall off over the
// last half pixel of a circle so that edges do not alias.
// The taps spread over the largest circle that reaches this pixel's tile
// (dof_tiles.frag) instead of max_radius, their count cut to keep the density
// of `samples` over max_radius: a tap beyond every circle would weigh 0, so
// only the sampling pattern changes, and a tile no circle reaches costs one
// fetch a pixel. With FOREIGN (the reduced-resolution path of dof.lua) it
// writes the light from other pixels and their share of the weight instead,
// for dof_composite.frag to lay over the full-size image.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, coc, tiles;
uniform float max_radius = 8.0; // pixels, >= 0
uniform int samples = 48;       // 1..256

out vec4 dst;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec3 centre = hdr_clamp(texelFetch(src, p, 0).rgb, HALF_MAX);
  vec2 cp = texelFetch(coc, p, 0).rg; // signed coc, eye depth
  float rmax = max(max_radius, 0.0);
  ivec2 tile = min(p / TILE, textureSize(tiles, 0) - 1);
  float reach_max = texelFetch(tiles, tile, 0).r;
  if (rmax < 0.5 || reach_max < 0.5) { // a zero-size blur, or no circle reaches beyond its own pixel
#ifdef FOREIGN
    dst = vec4(0.0);
#else
    dst = vec4(centre, 1.0);
#endif
    return;
  }
  float r = min(rmax, reach_max + 0.5);
  int all = clamp(samples, 1, 256);
  int n = clamp(int(ceil(float(all) * r * r / (rmax * rmax))), min(all, 8), all);
  float tap_area = PI * r * r / float(n);
  float w0 = min(1.0, 1.0 / (PI * max(cp.x * cp.x, 0.25)));
  vec3 sum = vec3(0.0);
  float wsum = w0;
  for (int i = 0; i < n; i++) {
    ivec2 off = ivec2(round(vogel_disc(i, n) * r));
    ivec2 q = clamp(p + off, ivec2(0), last);
    if (q == p) continue;
    vec2 cq = texelFetch(coc, q, 0).rg;
    float reach = abs(cq.x);
    if (cq.y > cp.y) reach = min(reach, abs(cp.x)); // behind p: no wider than p's own blur
    // A circle under half a pixel stays in its pixel: a sharp tap gives nothing.
    float w = saturate(reach - length(vec2(off)) + 0.5) * min(1.0, tap_area / (PI * max(cq.x * cq.x, 0.25)));
    sum += w * hdr_clamp(texelFetch(src, q, 0).rgb, HALF_MAX);
    wsum += w;
  }
#ifdef FOREIGN
  dst = vec4(hdr_clamp(sum / wsum, HALF_MAX), 1.0 - w0 / wsum);
#else
  dst = vec4(hdr_clamp((sum + w0 * centre) / wsum, HALF_MAX), 1.0);
#endif
}
