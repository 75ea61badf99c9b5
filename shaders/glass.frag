// Glass (the seed viewer's F8): the image seen through rippled glass. The
// glass's height is a sum of procedural ripples (concentric waves about
// two centres and a diagonal swell); its slope shifts each pixel's read by up
// to `strength` pixels, as refraction through a thin sheet would.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
uniform float strength = 8.0; // largest shift in pixels, >= 0
uniform float scale = 24.0;   // ripple wavelength in pixels, > 0
uniform vec3 tint = vec3(0.97); // what the glass lets through

out vec4 dst;

// Slope of the height field sum_i sin(k |p - c_i|) + sin(k (p.x + p.y) / 2)
// at p, each term's gradient written out (no derivative instructions, so a
// texel's result does not depend on its neighbours' quad).
vec2 slope(vec2 p, float k) {
  vec2 g = vec2(0.0);
  vec2 centres[2] = vec2[2](vec2(0.3, 0.35), vec2(0.7, 0.6));
  vec2 dim = vec2(textureSize(src, 0));
  for (int i = 0; i < 2; i++) {
    vec2 d = p - centres[i] * dim;
    float r = length(d);
    g += cos(k * r) * (r > 1e-3 ? d / r : vec2(0.0));
  }
  g += 0.5 * cos(0.5 * k * (p.x + p.y)) * vec2(1.0);
  return g / 2.5; // |g| <= 1
}

void main() {
  vec2 dim = vec2(textureSize(src, 0));
  float k = 2.0 * PI / max(scale, 1e-3);
  vec2 shift = slope(gl_FragCoord.xy, k) * max(strength, 0.0);
  vec2 at = clamp(gl_FragCoord.xy + shift, vec2(0.5), dim - 0.5) / dim;
  dst = vec4(hdr_clamp(texture(src, at).rgb * saturate(tint), HALF_MAX), 1.0);
}
