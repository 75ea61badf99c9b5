// The light propagation volumes' sums of two bounces added (scripts/lpv.lua,
// lpv.bounces): each bounce past the first propagates into sums of its own,
// which the next bounce's injection reads (lpv_inject.vert's BOUNCE: the
// light that bounced once more, not every bounce so far again), and this
// adds them to the bounces before for the lookup. Outputs: all r, g, b,
// then late r, g, b (lpv_lookup.frag's volumes).
#include "lpv.glsl"

uniform sampler2D all_r, all_g, all_b, late_r, late_g, late_b;       // the bounces before
uniform sampler2D more_r, more_g, more_b, more_late_r, more_late_g, more_late_b; // this bounce

layout(location = 0) out vec4 out_r;
layout(location = 1) out vec4 out_g;
layout(location = 2) out vec4 out_b;
layout(location = 3) out vec4 out_late_r;
layout(location = 4) out vec4 out_late_g;
layout(location = 5) out vec4 out_late_b;

void main() {
  ivec2 t = ivec2(gl_FragCoord.xy);
  out_r = lpv_finite(texelFetch(all_r, t, 0) + texelFetch(more_r, t, 0));
  out_g = lpv_finite(texelFetch(all_g, t, 0) + texelFetch(more_g, t, 0));
  out_b = lpv_finite(texelFetch(all_b, t, 0) + texelFetch(more_b, t, 0));
  out_late_r = lpv_finite(texelFetch(late_r, t, 0) + texelFetch(more_late_r, t, 0));
  out_late_g = lpv_finite(texelFetch(late_g, t, 0) + texelFetch(more_late_g, t, 0));
  out_late_b = lpv_finite(texelFetch(late_b, t, 0) + texelFetch(more_late_b, t, 0));
}
