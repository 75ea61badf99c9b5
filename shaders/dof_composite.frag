// Depth of field at reduced resolution, last step where hdr does not lay it
// over the image as it reads it: the full-size blurred image (dof_layer.glsl).
#include "dof_layer.glsl"

uniform sampler2D src; // full size: the image

out vec4 dst;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  dst = vec4(dof_over(texelFetch(src, p, 0).rgb, p, textureSize(src, 0)), 1.0);
}
