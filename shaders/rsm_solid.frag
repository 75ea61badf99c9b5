// The solid grid of the RSM views (rsm.solid_cell; scripts/shadow.lua's
// shadow.rsm_solid): one texel a cell of `cell` x `cell` RSM texels, holding
// the window depths (0..1, the light's view) between which every texel of
// the cell lies inside the first solid on the light's way: the farthest of
// their front faces (rsm_pos) and the nearest of their back faces (rsm_back,
// shadow.frag's RSM_BACK). A cell one of whose texels is empty or open (no
// back face) holds none (x > y). So a point of the cell's column between the
// two lies inside a solid for sure, whichever texel it falls on: the gather
// marches a segment over the cells (rsm.glsl's rsm_solid_between) instead
// of testing points against two texels each, and never blocks beside a
// surface (the cell's interval lies behind all its fronts).
#include "shadow.glsl"

uniform sampler2D rsm_pos, rsm_back;
uniform int cell = 8;

out vec2 solid;

void main() {
  ivec2 size = textureSize(rsm_pos, 0), first = ivec2(gl_FragCoord.xy) * cell;
  vec2 centre = (vec2(first) + 0.5 * float(cell)) / vec2(size);
  // The RSM view whose tile holds the cell (tiles are whole cells: shadow.lua).
  int view = -1;
  for (int i = 0; i < frame.counts.x && view < 0; i++) {
    ivec4 rsm = shadow_lights[i].cube;
    for (int v = rsm.y; v < rsm.y + rsm.z; v++) {
      vec4 r = shadow_views[v].rect;
      if (all(greaterThanEqual(centre, r.xy)) && all(lessThan(centre, r.xy + r.zw))) view = v;
    }
  }
  solid = vec2(1.0, 0.0); // none
  if (view < 0) return;
  mat4 vp = shadow_views[view].view_proj;
  float front = 0.0, back = 1.0;
  for (int y = 0; y < cell; y++) {
    for (int x = 0; x < cell; x++) {
      ivec2 a = min(first + ivec2(x, y), size - 1);
      vec4 f = texelFetch(rsm_pos, a, 0), b = texelFetch(rsm_back, a, 0);
      if (f.w > 0.0 || b.w > 0.0) return; // empty, or no face closes it
      vec4 cf = vp * vec4(f.xyz, 1.0), cb = vp * vec4(b.xyz, 1.0);
      if (cf.w <= 1e-12 || cb.w <= 1e-12) return;
      front = max(front, cf.z / cf.w * 0.5 + 0.5);
      back = min(back, cb.z / cb.w * 0.5 + 0.5);
    }
  }
  if (front < back) solid = vec2(front, back);
}
