// The light each of the next bounce's points receives (scripts/lpv.lua,
// lpv.bounces): texel k of a `bounce_width`-wide target holds E / pi at
// point k of lpv_inject.vert's BOUNCE (lpv_points.glsl) from the last
// bounce's volumes (lpv_light.glsl), which its albedo sends on. A pass
// rather than the points' own lookup: llvmpipe runs a points pass's vertex
// shader on one thread, and the lookup made a bounce's injection cost 60
// times the first's.
#include "lpv_points.glsl"
#include "lpv_light.glsl"

uniform int bounce_width = 64, bounce_points = 0;

out vec4 light;

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  int k = t.y * max(bounce_width, 1) + t.x, c;
  vec3 p, n, flux;
  light = vec4(0.0, 0.0, 0.0, 1.0);
  if (k < bounce_points && lpv_point(k, c, p, n, flux)) light.rgb = lpv_light(p, n);
}
