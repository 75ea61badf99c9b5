// Depth of field at half size, step 1: each texel of the half-size image
// takes the mean colour of the 2 x 2 pixels under it and the circle of
// confusion of the nearest of them (scaled to the reduced pixels), so a
// foreground's blur still spreads and a sharp foreground still shields what
// lies behind it. The circle comes from the G-buffer's depth here (dof.glsl):
// no full-size circle target is written or read. It goes to the image's
// alpha too, so that each of the gather's taps is one read.
#include "dof.glsl"

uniform sampler2D src;

layout(location = 0) out vec4 dst;
layout(location = 1) out vec4 dst_coc;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * 2;
  // The block's mean colour in one filtered read (block_mean), clamped once:
  // dof.reduce 10.3 -> 6.8 ms against four fetches (512x384, moving, load 9-10).
  vec3 c = hdr_clamp(block_mean(src, base).rgb, HALF_MAX);
  // The block's depths in one gather at its centre (clamped at the border, as the colours are).
  vec4 d = textureGather(dpt, vec2(base + 1) / vec2(textureSize(dpt, 0)), 0);
  float nearest = min(min(eye_depth(d.x), eye_depth(d.y)), min(eye_depth(d.z), eye_depth(d.w)));
  float circle = dof_coc(nearest, dof_focus()) * 0.5;
  dst = vec4(c, circle);
  dst_coc = vec4(circle, nearest, 0.0, 0.0);
}
