// Separable Gaussian blur, one axis a pass (seed 000, Listing 3 step 4).
// With MASK, texels whose mask.a < 0.5 (background) neither give nor take:
// indirect light does not bleed into the sky and back.
#include "common.glsl"

in vec2 uv;
uniform sampler2D src;
#ifdef MASK
uniform sampler2D mask;
#endif
uniform ivec2 axis = ivec2(1, 0); // (1, 0) horizontal, (0, 1) vertical
uniform int radius = 4;           // taps each side; sigma = radius / 2

out vec4 dst;

float weight_at(ivec2 q) {
#ifdef MASK
  return step(0.5, texelFetch(mask, q, 0).a);
#else
  return 1.0;
#endif
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(src, 0) - 1;
  vec4 centre = texelFetch(src, p, 0);
  if (weight_at(p) == 0.0 || radius < 1) {
    dst = centre;
    return;
  }
  float sigma = 0.5 * float(radius), inv2s2 = 0.5 / (sigma * sigma);
  vec4 sum = vec4(0.0);
  float wsum = 0.0;
  for (int i = -radius; i <= radius; i++) {
    ivec2 q = clamp(p + axis * i, ivec2(0), last);
    float w = exp(-float(i * i) * inv2s2) * weight_at(q);
    sum += w * texelFetch(src, q, 0);
    wsum += w;
  }
  dst = wsum > 0.0 ? sum / wsum : centre; // the centre tap has weight 1
}
