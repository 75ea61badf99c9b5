// Depth of field at reduced resolution laid over the image (scripts/dof.lua):
// the gather's light from other pixels (rgb, already weighted) and its share
// of the pixel (a), L = (1 - a) L_p + foreign, so a sharp pixel no blurred
// circle covers keeps its own value exactly. dof_composite.frag writes it;
// with hdr on, hdr's passes lay it over the image as they read it (DOF_LAYER:
// no full-size pass writes the blurred image).
// The reduced result comes to full size as ISR's does (isr_light.frag, seed
// 000 eq 27-28): bilinear weights over the 2 x 2 texels around the pixel,
// each divided by EPS_Z plus its depth's distance from the pixel's, relative
// to that depth. Where blocks of pixels are averaged (dof_over_reduced:
// bloom's bright pass over the reduced image, hdr's meter over pixels) a
// texel's own gather is laid over them without upsampling.
#ifndef LIMN_DOF_LAYER_GLSL
#define LIMN_DOF_LAYER_GLSL
#include "post.glsl"

uniform sampler2D foreign; // reduced: the gather's result (dof_gather.frag, FOREIGN)

// At reduced texel q, the colour c of its image (dof.small) or of a pixel under it: the blurred colour.
vec3 dof_over_reduced(vec3 c, ivec2 q) {
  vec4 f = texelFetch(foreign, min(q, textureSize(foreign, 0) - 1), 0);
  return hdr_clamp((1.0 - saturate(f.a)) * hdr_clamp(c, HALF_MAX) + hdr_clamp(f.rgb, HALF_MAX), HALF_MAX);
}

#ifndef DOF_REDUCED_ONLY
uniform sampler2D dpt;       // full size: the G-buffer's linear depth
uniform sampler2D small_coc; // reduced: (coc, eye depth) (dof_reduce.frag)

const float DOF_EPS_Z = 0.01;

// At full-size pixel p of an image of `size` pixels, its colour c: the blurred colour.
vec3 dof_over(vec3 c, ivec2 p, ivec2 size) {
  ivec2 small = textureSize(foreign, 0), last = small - 1;
  c = hdr_clamp(c, HALF_MAX);
  float z = eye_depth(texelFetch(dpt, p, 0).r);
  vec2 t = (vec2(p) + 0.5) * vec2(small) / vec2(size) - 0.5;
  ivec2 base = ivec2(floor(t));
  vec2 fr = t - floor(t);
  // The four texels' depths in one gather at their shared corner (clamped at
  // the border), in the order (0, 0), (1, 0), (0, 1), (1, 1) (on llvmpipe
  // this pass took 43 -> 30 ms with the depths gathered); their light in
  // four fetches: a gather reads four whole texels for one channel of each,
  // so four gathers of the four channels read 16 texels.
  vec2 corner = (vec2(base) + 1.0) / vec2(small);
  vec4 zs = textureGather(small_coc, corner, 1).wzxy;
  vec4 w = vec4((1.0 - fr.x) * (1.0 - fr.y), fr.x * (1.0 - fr.y), (1.0 - fr.x) * fr.y, fr.x * fr.y) /
           (DOF_EPS_Z + abs(z - zs) / max(z, 1e-12));
  float wsum = w.x + w.y + w.z + w.w;
  vec4 sum = w.x * texelFetch(foreign, clamp(base, ivec2(0), last), 0) +
             w.y * texelFetch(foreign, clamp(base + ivec2(1, 0), ivec2(0), last), 0) +
             w.z * texelFetch(foreign, clamp(base + ivec2(0, 1), ivec2(0), last), 0) +
             w.w * texelFetch(foreign, clamp(base + ivec2(1, 1), ivec2(0), last), 0);
  vec4 f = wsum > 1e-12 ? sum / wsum : texelFetch(foreign, clamp(ivec2(t + 0.5), ivec2(0), last), 0);
  return hdr_clamp((1.0 - saturate(f.a)) * c + hdr_clamp(f.rgb, HALF_MAX), HALF_MAX);
}
#endif
#endif
