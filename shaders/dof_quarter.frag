// Depth of field at half size, step 1c: the half-size image (dof_reduce.frag)
// at half its size again, for the gather's taps where every circle near a
// tile is large (dof_gather.frag): each texel the mean colour of the 2 x 2
// under it (one filtered read at their centre, a quarter each; clamped at the
// border) and the circle of the nearest of them, the smallest signed one (the
// circle grows with depth), in half-size pixels as dof.small holds it, so a
// blurred foreground still spreads and a sharp one still shields.
#include "post.glsl"

uniform sampler2D src; // dof.small: clamped colour, signed circle

out vec4 dst;

void main() {
  ivec2 corner = ivec2(gl_FragCoord.xy) * 2;
  vec4 circles = textureGather(src, vec2(corner + 1) / vec2(textureSize(src, 0)), 3);
  dst = vec4(block_mean(src, corner).rgb, min(min(circles.x, circles.y), min(circles.z, circles.w)));
}
