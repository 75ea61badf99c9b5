// Camera motion blur: each pixel's world position (rebuilt from linear depth,
// seed 000 eq 23-24) is projected with the previous frame's view-projection;
// the screen motion since then, scaled by `strength` (the fraction of a frame
// the shutter is open) and capped at `max_length` pixels, is averaged over
// `samples` reads centred on the pixel. A still camera changes nothing.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, dpt;
uniform float strength = 0.5;    // 0..4
uniform float max_length = 32.0; // pixels, >= 0
uniform int samples = 12;        // 1..64

out vec4 dst;

void main() {
  vec3 centre = hdr_clamp(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb, HALF_MAX);
  float d = texture(dpt, uv).r;
  // The background has no depth: take the far plane, so that turning the
  // camera blurs it too.
  vec3 p = position_from_depth(uv, d > 0.0 ? clamp(d, 0.0, 1.0) : 1.0);
  vec4 prev = frame.prev_view_proj * vec4(p, 1.0);
  vec2 motion = vec2(0.0);
  if (prev.w > EPS) { // behind the last camera: no trustworthy motion
    vec2 prev_uv = prev.xy / prev.w * 0.5 + 0.5;
    motion = (uv - prev_uv) * frame.output_size.xy * clamp(strength, 0.0, 4.0); // pixels
  }
  float len = length(motion), cap = max(max_length, 0.0);
  if (!(len > 0.5) || cap < 0.5) { // under half a pixel (or NaN): nothing to blur
    dst = vec4(centre, 1.0);
    return;
  }
  motion *= min(len, cap) / len;
  int n = clamp(samples, 1, 64);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < n; i++) {
    float t = n > 1 ? float(i) / float(n - 1) - 0.5 : 0.0;
    sum += hdr_clamp(texture(src, uv + motion * t * frame.output_size.zw).rgb, HALF_MAX);
  }
  dst = vec4(sum / float(n), 1.0);
}
