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
  // The depths of the four texels around the pixel in one gather at their
  // shared corner (clamped at the border; as coarse.glsl does), in the order
  // (0, 0), (1, 0), (0, 1), (1, 1): cheaper than four fetches on llvmpipe.
  vec2 corner = (vec2(base) + 1.0) / vec2(textureSize(foreign, 0));
  vec4 zs = textureGather(small_coc, corner, 1).wzxy;
  vec4 w = vec4((1.0 - fr.x) * (1.0 - fr.y), fr.x * (1.0 - fr.y), (1.0 - fr.x) * fr.y, fr.x * fr.y) /
           (EPS_Z + abs(z - zs) / max(z, 1e-12));
  // Whole texels, one fetch each: llvmpipe's gather reads four whole texels
  // for the one channel it returns. dof_gather.frag wrote them clamped (no
  // NaN, in [0, HALF_MAX]), so their weighted mean needs no clamp, and the
  // sum over the pixel's own light only a cap (0.82-1.04 of the time of the
  // composite that gathered and clamped every step, three runs in one
  // process at 512x384, load 4-7).
  ivec2 b0 = clamp(base, ivec2(0), last), b1 = min(base + 1, last);
  vec4 f = (w.x * texelFetch(foreign, b0, 0) + w.y * texelFetch(foreign, ivec2(b1.x, b0.y), 0) +
            w.z * texelFetch(foreign, ivec2(b0.x, b1.y), 0) + w.w * texelFetch(foreign, b1, 0)) /
           max(w.x + w.y + w.z + w.w, 1e-30);
  dst = vec4(min((1.0 - saturate(f.a)) * c + f.rgb, vec3(HALF_MAX)), 1.0);
}
