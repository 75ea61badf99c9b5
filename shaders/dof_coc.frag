// Depth of field, step 1 at full size (dof.downsample 1): the signed circle
// of confusion in pixels and the eye depth (dof.glsl), for the gather to
// read at every tap. At reduced size dof_reduce.frag computes it instead.
#include "dof.glsl"

out vec4 coc;

void main() {
  float z = eye_depth(texelFetch(dpt, ivec2(gl_FragCoord.xy), 0).r);
  coc = vec4(dof_coc(z, dof_focus()), z, 0.0, 0.0);
}
