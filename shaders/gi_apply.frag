// Applies a screen-space GI result, already at full size, to the frame's
// direct light `lit` (lights and shadows, no ambient term; seed 001, lines
// 1301-1313). sky = k_a L_a albedo is the ambient term, the light of the sky
// in the physical variants, the only light occlusion may take away: the
// direct pass's (gbuffer.glsl's ambient_light), k_d albedo for a pbr surface,
// so a metal gets none.
// Background keeps the lit colour, plus the sky seen there. One of:
//  PHYSICAL  out = lit + A sky + B     SSDO: accessibility and bounce
//  MERGED    out = M (lit + sky + B)   SSDO modulation factor and bounce (the seed's)
//  TWO_STEP  out = L_dir + L_ind       the original SSDO's two results
//  AO        out = lit + A sky         SSAO's accessibility (a.r) on the sky alone;
//            with AO_LIT out = A (lit + sky), seed 001's darkening of everything
#include "gbuffer.glsl"

in vec2 uv;
uniform sampler2D lit, clr, mat;
uniform sampler2D a;
#ifdef SKY
uniform sampler2D nrm;
#endif
#ifndef AO
uniform sampler2D b;
#endif
uniform vec3 ambient = vec3(0.0);

out vec4 result;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 l = texelFetch(lit, p, 0).rgb;
  vec4 m = texelFetch(mat, p, 0);
  if (m.a < 0.5) { // the lit colour (background) and the sky, which the direct pass leaves out
    result = vec4(l + sky_seen(uv), 1.0);
    return;
  }
#ifdef SKY
  vec4 n = gbuffer_normal_decode(texelFetch(nrm, p, 0));
#else
  vec4 n = vec4(0.0, 1.0, 0.0, 0.0); // no sky: the ambient term is the same every way
#endif
  Surface s = gbuffer_decode(texelFetch(clr, p, 0), n, 0.0, m, uv); // no position is needed
  vec3 sky = ambient_light(s, ambient);
  vec4 x = texelFetch(a, p, 0);
#if defined(PHYSICAL)
  vec3 c = l + saturate(x.r) * sky + texelFetch(b, p, 0).rgb;
#elif defined(MERGED)
  vec3 c = saturate(x.rgb) * (l + sky + texelFetch(b, p, 0).rgb);
#elif defined(TWO_STEP)
  vec3 c = x.rgb + texelFetch(b, p, 0).rgb;
#elif defined(AO_LIT)
  vec3 c = saturate(x.r) * (l + sky);
#else
  vec3 c = l + saturate(x.r) * sky;
#endif
  result = vec4(c, 1.0);
}
