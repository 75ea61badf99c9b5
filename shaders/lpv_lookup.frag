// The light propagation volumes' light at each pixel of the (coarse)
// G-buffer (seed 003, section 5.3.6's lookup; scripts/lpv.lua), on POV-Ray's
// scale (/work/shared/design/gi-scale.md): E / pi, what the composite
// (isr_light.frag) multiplies by k_d albedo; lpv_light.glsl computes it.
//
// Output: rgb = E / pi, a = 1, or with SKY_OCCLUSION the share of the sky
// the pixel sees past the surfaces of the geometry volume (open_sky), which
// the direct pass's composite multiplies the ambient term by.
// With STRIDE, each texel reads the G-buffer, STRIDE times finer, at its
// block's centre (isr.coarse_view); with Z it also writes that depth / far,
// 0 where nothing is drawn, into z (the view's depth).
#include "gbuffer.glsl"
#include "lpv_light.glsl"

#ifndef STRIDE
#define STRIDE 1
#endif

in vec2 uv;
uniform sampler2D clr, nrm, dpt, mat;         // (coarse) G-buffer

#ifdef SKY_OCCLUSION
#include "halton.glsl"

const int SKY_DIRECTIONS = 8;

// The cosine-weighted share of the sky p facing n sees past the geometry
// volume's surfaces: lpv_sky_through along SKY_DIRECTIONS fixed
// cosine-weighted directions (a golden-angle spiral).
float open_sky(vec3 p, vec3 n) {
  mat3 around = tangent_frame(n);
  float open = 0.0;
  for (int i = 0; i < SKY_DIRECTIONS; i++)
    open += lpv_sky_through(p, n, around * hemisphere_cosine(vec2(fract(0.618034 * float(i)), (float(i) + 0.5) / float(SKY_DIRECTIONS))));
  return open / float(SKY_DIRECTIONS);
}
#endif

layout(location = 0) out vec4 result;
#ifdef Z
layout(location = 1) out float z;
#endif

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  Surface s = gbuffer_fetch(clr, nrm, dpt, mat, block_centre(px, STRIDE, textureSize(dpt, 0)));
#ifdef Z
  z = s.covered ? s.depth01 : 0.0;
#endif
  if (!s.covered) {
    result = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  result = vec4(lpv_light(s.p, s.n), 1.0);
#ifdef SKY_OCCLUSION
  result.a = open_sky(s.p, s.n);
#endif
}
