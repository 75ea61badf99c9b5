// Applies a screen-space GI result, already at full size, to the direct-lit
// image (seed 001, lines 1301-1313: "the bounce and the intensity is then
// darkened using the modulation factor, then summed together"). Background
// keeps the lit colour. One of:
//  MERGED    out = M (lit + B)          SSDO modulation factor and bounce
//  TWO_STEP  out = L_dir + L_ind        the original SSDO's two results
//  AO        out = A lit                SSAO's darkening factor (a.r)
#include "common.glsl"

in vec2 uv;
uniform sampler2D lit, mat;
uniform sampler2D a;
#ifndef AO
uniform sampler2D b;
#endif

out vec4 result;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 l = texelFetch(lit, p, 0).rgb;
  if (texelFetch(mat, p, 0).a < 0.5) {
    result = vec4(l, 1.0);
    return;
  }
  vec4 x = texelFetch(a, p, 0);
#if defined(MERGED)
  vec3 c = saturate(x.rgb) * (l + texelFetch(b, p, 0).rgb);
#elif defined(TWO_STEP)
  vec3 c = x.rgb + texelFetch(b, p, 0).rgb;
#else
  vec3 c = saturate(x.r) * l;
#endif
  result = vec4(c, 1.0);
}
