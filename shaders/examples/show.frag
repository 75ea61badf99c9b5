// The tutorial's debug view (scripts/examples/debug_view.lua): a target's
// values as they are, times `scale` plus `offset`, in a float target; with
// NORMAL (the G-buffer's normals) the unit normal its texels encode.
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;
uniform float scale = 1.0;
uniform float offset = 0.0;

out vec4 dst;

void main() {
  vec4 v = texelFetch(src, ivec2(gl_FragCoord.xy), 0);
#ifdef NORMAL
  v = gbuffer_normal_decode(v);
#endif
  dst = vec4(v.rgb * scale + offset, 1.0);
}
