// Depth of field at reduced resolution, last step: the gather's light from
// other pixels (rgb, already weighted) and its share of the pixel (a) over
// the full-size image, L = (1 - a) L_p + foreign, so a sharp pixel no blurred
// circle covers keeps its own value exactly. The reduced result comes to full
// size as ISR's does (isr_light.frag, seed 000 eq 27-28): bilinear weights
// over the 2 x 2 texels around the pixel, each divided by EPS_Z plus its
// depth's distance from the pixel's, relative to that depth.
#include "post.glsl"

uniform sampler2D src, dpt;             // full size: image, G-buffer's linear depth
uniform sampler2D foreign, small_coc;   // reduced: gather result, (coc, eye depth)

out vec4 dst;

const float EPS_Z = 0.01;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(foreign, 0) - 1;
  vec3 c = hdr_clamp(texelFetch(src, p, 0).rgb, HALF_MAX);
  float z = eye_depth(texelFetch(dpt, p, 0).r);
  vec2 t = (vec2(p) + 0.5) * vec2(textureSize(foreign, 0)) / vec2(textureSize(src, 0)) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 fr = t - floor(t);
  // The four texels around the pixel, a channel of all four in one gather at
  // their shared corner (clamped at the border; as coarse.glsl does), in the
  // order (0, 0), (1, 0), (0, 1), (1, 1): 5 reads instead of 8 (on llvmpipe
  // this pass took 43 -> 30 ms with the depths alone gathered).
  vec2 corner = (vec2(base) + 1.0) / vec2(textureSize(foreign, 0));
  vec4 zs = textureGather(small_coc, corner, 1).wzxy;
  vec4 w = vec4((1.0 - fr.x) * (1.0 - fr.y), fr.x * (1.0 - fr.y), (1.0 - fr.x) * fr.y, fr.x * fr.y) /
           (EPS_Z + abs(z - zs) / max(z, 1e-12));
  float wsum = w.x + w.y + w.z + w.w;
  vec4 sum = vec4(dot(w, textureGather(foreign, corner, 0).wzxy), dot(w, textureGather(foreign, corner, 1).wzxy),
                  dot(w, textureGather(foreign, corner, 2).wzxy), dot(w, textureGather(foreign, corner, 3).wzxy));
  vec4 f = wsum > 1e-12 ? sum / wsum : texelFetch(foreign, clamp(ivec2(t + 0.5), ivec2(0), last), 0);
  dst = vec4(hdr_clamp((1.0 - saturate(f.a)) * c + hdr_clamp(f.rgb, HALF_MAX), HALF_MAX), 1.0);
}
