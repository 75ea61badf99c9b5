// Depth of field at reduced resolution, last step: the full-size image
// with the gather's light laid over it (dof.glsl's dof_composite).
#include "dof.glsl"

uniform sampler2D src;                // full size: the image (dpt: dof.glsl's)
uniform sampler2D foreign, small_coc; // reduced: gather result, (coc, eye depth)

out vec4 dst;

void main() { dst = vec4(dof_composite(src, foreign, small_coc, ivec2(gl_FragCoord.xy)), 1.0); }
