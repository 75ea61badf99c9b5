// Radial (zoom) blur (the seed viewer's F9): each pixel averages `samples`
// reads along the line towards `centre`, reaching the fraction `strength`
// of the way there. strength 0 or one sample leaves the image unchanged.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
uniform vec2 centre = vec2(0.5); // in uv, (0, 0) the bottom left
uniform float strength = 0.1;    // 0..1
uniform int samples = 16;        // 1..64

out vec4 dst;

void main() {
  int n = clamp(samples, 1, 64);
  vec2 towards = (centre - uv) * saturate(strength);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < n; i++) {
    float t = n > 1 ? float(i) / float(n - 1) : 0.0;
    sum += hdr_clamp(texture(src, uv + towards * t).rgb, HALF_MAX);
  }
  dst = vec4(sum / float(n), 1.0);
}
