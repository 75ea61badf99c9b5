// Depth of field, step 2: a gather that acts as a scatter. Each tap q of a
// disc of max_radius pixels (a Vogel spiral, `samples` taps) adds to this
// pixel p only if its own circle of confusion reaches p:
//   reach(q) = |coc_q|, but no more than |coc_p| when q lies behind p.
// The signed circle grows with depth (dof.glsl) and where two differ only in
// depth both are at the cap, so "behind" is coc_q > coc_p: a tap reads the
// circle alone, which at half size (FOREIGN) is the image's alpha.
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
// for dof_composite.frag to lay over the full-size image. There, where every
// circle near the tile spans QUARTER_REACH half-size pixels or more, all on
// one side of the focus (the tiles' signed span), the taps read the image at
// half its size again (dof_quarter.frag), a quarter as many for the same
// density: each is the mean of four texels, read filtered at its place (the
// circles it blends are alike), and a blur that wide hides the coarser grid.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, tiles;
#ifdef FOREIGN
uniform sampler2D quarter; // dof_quarter.frag: mean colour, nearest circle (half-size pixels)
#else
uniform sampler2D coc; // (signed coc, eye depth) at full size; at half size src.a holds the circle
#endif
uniform float max_radius = 8.0; // pixels, >= 0
uniform int samples = 48;       // 1..256

out vec4 dst;

// A texel's light and signed circle of confusion. The half-size image
// (FOREIGN) is written clamped (dof_reduce.frag): read as it is; the
// full-size one is any lit image, clamped as read.
vec4 tap(ivec2 q) {
#ifdef FOREIGN
  return texelFetch(src, q, 0);
#else
  return vec4(hdr_clamp(texelFetch(src, q, 0).rgb, HALF_MAX), texelFetch(coc, q, 0).r);
#endif
}

// Smallest circle (half-size pixels) for the quarter-size taps: one of their
// texels, so no circle is narrower than the grid it is read on.
const float QUARTER_REACH = 2.0;

// What tap sq, at distance d from p, adds: its light if its circle reaches p,
// over its own circle's area.
void add_tap(vec4 sq, float d, float cp, float tap_area, inout vec3 sum, inout float wsum) {
  float cq = sq.a, reach = abs(cq);
  if (cq > cp) reach = min(reach, abs(cp)); // behind p: no wider than p's own blur
  // A circle under half a pixel stays in its pixel: a sharp tap gives nothing.
  float w = saturate(reach - d + 0.5) * min(1.0, tap_area / (PI * max(cq * cq, 0.25)));
  sum += w * sq.rgb;
  wsum += w;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec4 sp = tap(p);
  vec3 centre = hdr_clamp(sp.rgb, HALF_MAX);
  float cp = sp.a; // signed coc
  float rmax = max(max_radius, 0.0);
  ivec2 tile = min(p / TILE, textureSize(tiles, 0) - 1);
  vec2 span = texelFetch(tiles, tile, 0).rg; // least and greatest signed circle near the tile
  float reach_max = max(-span.x, span.y);
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
  float w0 = min(1.0, 1.0 / (PI * max(cp * cp, 0.25)));
  vec3 sum = vec3(0.0);
  float wsum = w0;
#ifdef FOREIGN
  // Two loops, one of which takes no step (a group lies in one tile):
  // llvmpipe runs both sides of an `if` for every group, but a loop only
  // for as many steps as its pixels need (and one more, masked).
  bool coarse = span.x >= QUARTER_REACH || span.y <= -QUARTER_REACH;
  int nq = coarse ? (n + 3) / 4 : 0; // quarter-size taps
  n = coarse ? 0 : n;
  float quarter_area = PI * r * r / float(max(nq, 1));
  vec2 to_uv = 0.5 / vec2(textureSize(quarter, 0)); // half-size pixels to the quarter image's uv
  vec2 dir_q = vec2(1.0, 0.0);
  for (int i = 0; i < nq; i++, dir_q = vogel_next(dir_q)) {
    vec2 off = vogel_point(i, nq, dir_q) * r;
    add_tap(texture(quarter, (vec2(p) + 0.5 + off) * to_uv), length(off), cp, quarter_area, sum, wsum);
  }
#endif
  float tap_area = PI * r * r / float(max(n, 1));
  vec2 dir = vec2(1.0, 0.0); // point i's direction (post.glsl's vogel_next)
  for (int i = 0; i < n; i++, dir = vogel_next(dir)) {
    ivec2 off = ivec2(round(vogel_point(i, n, dir) * r));
    ivec2 q = clamp(p + off, ivec2(0), last);
    if (q == p) continue;
    add_tap(tap(q), length(vec2(off)), cp, tap_area, sum, wsum);
  }
#ifdef FOREIGN
  dst = vec4(hdr_clamp(sum / wsum, HALF_MAX), 1.0 - w0 / wsum);
#else
  dst = vec4(hdr_clamp((sum + w0 * centre) / wsum, HALF_MAX), 1.0);
#endif
}
