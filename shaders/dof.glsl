// Depth of field's circle of confusion (scripts/dof.lua), shared by the
// passes that compute it from the G-buffer's linear depth (dpt = depth /
// far; far is frame.clip.y): signed in pixels, negative in front of the
// focus, positive behind.
//   RANGE: |coc| = max_radius * saturate(|z - focus| / range)
//   LENS (thin lens, focal length f, aperture A = f / N, focused at s):
//          coc = A f (z - s) / (z (s - f)) on the sensor, in pixels
//          through the sensor height, capped at max_radius.
// The focus is clamped into [near, far] and beyond the focal length, so a
// focus on either plane, or closer than the lens can focus, stays finite.
// Lengths of 0 are relative to the view (scripts/dof.lua), so any unit gives
// the same image: focus the depth at the centre, range focus / 3, focal
// length focus / 70, sensor 2 f tan(fov_y / 2).
#ifndef LIMN_DOF_GLSL
#define LIMN_DOF_GLSL
#include "post.glsl"

uniform sampler2D dpt;
uniform float focus = 0.0;        // world units from the eye; 0: the depth at the centre
uniform float range = 0.0;        // RANGE: depth distance to full blur; 0: focus / 3
uniform float max_radius = 8.0;   // pixels, >= 0
uniform float focal_length = 0.0; // LENS: world units; 0: focus / 70 (50 mm at 3.5 m)
uniform float f_number = 2.8;     // LENS: > 0
uniform float sensor = 0.0;       // LENS: sensor height, world units; 0: from the field of view

// The focus distance: the option, or the depth at the image's centre.
float dof_focus() {
  return focus > 0.0 ? focus : eye_depth(texelFetch(dpt, textureSize(dpt, 0) / 2, 0).r);
}

// The signed circle of confusion, in full-size pixels, of eye depth z.
float dof_coc(float z, float focused) {
  float near = frame.clip.x, far = max(frame.clip.y, near);
  float tiny = near * 1e-6; // a length under anything the view resolves
  float cap = max(max_radius, 0.0);
  float c;
#ifdef LENS
  float f = max(focal_length > 0.0 ? focal_length : focused / 70.0, tiny);
  float s = clamp(focused, max(near, 1.001 * f), max(far, 1.001 * f));
  float aperture = f / max(f_number, 1e-3);
  float on_sensor = aperture * f * (z - s) / (max(z, tiny) * (s - f)); // s - f >= 0.001 f
  float height = sensor > 0.0 ? sensor : 2.0 * f * frame.clip.w;
  c = on_sensor / max(height, tiny) * frame.output_size.y;
#else
  float s = clamp(focused, near, far);
  float r = range > 0.0 ? range : s / 3.0;
  c = sign(z - s) * saturate(abs(z - s) / max(r, tiny)) * cap;
#endif
  return clamp(c, -cap, cap);
}

// Depth of field at reduced resolution, last step: the gather's light from
// other pixels (rgb, already weighted) and its share of the pixel (a) over
// the full-size image, L = (1 - a) L_p + foreign, so a sharp pixel no blurred
// circle covers keeps its own value exactly. The reduced result comes to full
// size as ISR's does (isr_light.frag, seed 000 eq 27-28): bilinear weights
// over the 2 x 2 texels around the pixel, each divided by EPS_Z plus its
// depth's distance from the pixel's, relative to that depth. src: the
// full-size image; foreign: dof_gather.frag's; small_coc: dof_reduce.frag's
// (coc, eye depth). dof_composite.frag writes it; hdr_tonemap.frag computes
// it as it reads the image where scripts/post.lua folds the composite in.
const float DOF_EPS_Z = 0.01;

vec3 dof_composite(sampler2D src, sampler2D foreign, sampler2D small_coc, ivec2 p) {
  ivec2 last = textureSize(foreign, 0) - 1;
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
           (DOF_EPS_Z + abs(z - zs) / max(z, 1e-12));
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
  return min((1.0 - saturate(f.a)) * c + f.rgb, vec3(HALF_MAX));
}

// The composite at the reduced size, texel q: the half-size image (written
// clamped, dof_reduce.frag) under the gather's share, plus its foreign
// light, no upsampling: what the passes that reduce the image further read
// where the full-size composite is not written (bloom_bright.frag, the
// first level of hdr_reduce.frag).
vec3 dof_composite_small(sampler2D small, sampler2D foreign, ivec2 q) {
  q = min(q, textureSize(foreign, 0) - 1);
  vec4 f = texelFetch(foreign, q, 0);
  return min((1.0 - saturate(f.a)) * texelFetch(small, q, 0).rgb + f.rgb, vec3(HALF_MAX));
}
#endif
