// Depth of field at reduced resolution, last step: the gather's light from
// other pixels (rgb, already weighted) and its share of the pixel (a) over
// the full-size image, L = (1 - a) L_p + foreign, so a sharp pixel no blurred
// circle covers keeps its own value exactly. The reduced result comes to full
// size as ISR's does (isr_light.frag, seed 000 eq 27-28): bilinear weights
// over the 2 x 2 texels around the pixel, each divided by EPS_Z plus its
// depth's distance from the pixel's, relative to that depth.
#include "post.glsl"

uniform sampler2D src, coc;             // full size: image, (signed coc, eye depth)
uniform sampler2D foreign, small_coc;   // reduced: gather result, (coc, eye depth)

out vec4 dst;

const float EPS_Z = 0.01;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(foreign, 0) - 1;
  vec3 c = hdr_clamp(texelFetch(src, p, 0).rgb, HALF_MAX);
  float z = texelFetch(coc, p, 0).g;
  vec2 t = (vec2(p) + 0.5) * vec2(textureSize(foreign, 0)) / vec2(textureSize(src, 0)) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 fr = t - floor(t);
  vec4 sum = vec4(0.0);
  float wsum = 0.0;
  for (int i = 0; i < 4; i++) {
    ivec2 o = ivec2(i & 1, i >> 1), q = clamp(base + o, ivec2(0), last);
    vec2 wb = mix(1.0 - fr, fr, vec2(o));
    float dz = abs(z - texelFetch(small_coc, q, 0).g) / max(z, 1e-12);
    float w = wb.x * wb.y / (EPS_Z + dz);
    sum += w * texelFetch(foreign, q, 0);
    wsum += w;
  }
  vec4 f = wsum > 1e-12 ? sum / wsum : texelFetch(foreign, clamp(ivec2(t + 0.5), ivec2(0), last), 0);
  dst = vec4(hdr_clamp((1.0 - saturate(f.a)) * c + hdr_clamp(f.rgb, HALF_MAX), HALF_MAX), 1.0);
}
