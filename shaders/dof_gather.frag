// Depth of field, step 2: a gather that acts as a scatter. Each tap q of a
// disc of max_radius pixels (a Vogel spiral, `samples` taps) adds to this
// pixel p only if its own circle of confusion reaches p:
//   radius(q) = |coc_q|, but no more than |coc_p| when q lies behind p.
// So a blurred foreground spreads over a sharp background (its large circle
// reaches p whatever p's own), while a blurred background cannot bleed onto
// a sharp foreground, and a sharp foreground (circle ~0) reaches no blurred
// background pixel beside it. Weights fall off over the last pixel of a
// circle so that edges do not alias. p itself always counts.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src, coc;
uniform float max_radius = 8.0; // pixels, >= 0
uniform int samples = 48;       // 1..256

out vec4 dst;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec3 centre = hdr_clamp(texelFetch(src, p, 0).rgb, HALF_MAX);
  vec2 cp = texelFetch(coc, p, 0).rg; // signed coc, eye depth
  float rmax = max(max_radius, 0.0);
  if (rmax < 0.5) { // a zero-size blur
    dst = vec4(centre, 1.0);
    return;
  }
  vec3 sum = centre;
  float wsum = 1.0;
  int n = clamp(samples, 1, 256);
  for (int i = 0; i < n; i++) {
    ivec2 off = ivec2(round(vogel_disc(i, n) * rmax));
    ivec2 q = clamp(p + off, ivec2(0), last);
    if (q == p) continue;
    vec2 cq = texelFetch(coc, q, 0).rg;
    float reach = abs(cq.x);
    if (cq.y > cp.y) reach = min(reach, abs(cp.x)); // behind p: no wider than p's own blur
    // A circle under half a pixel stays in its pixel: a sharp tap gives nothing.
    float w = saturate(reach - length(vec2(off)) + 0.5);
    sum += w * hdr_clamp(texelFetch(src, q, 0).rgb, HALF_MAX);
    wsum += w;
  }
  dst = vec4(hdr_clamp(sum / wsum, HALF_MAX), 1.0);
}
