// limn bench: `count` independent texel fetches a pixel from its 8x8
// neighbourhood (cache-friendly, so close to the machine's best rate); the
// time per fetch calibrates what passes are measured against.
in vec2 uv;
uniform sampler2D src;
uniform int count = 16;

out vec4 sum;

void main() {
  ivec2 size = textureSize(src, 0), p = ivec2(gl_FragCoord.xy);
  vec4 acc = vec4(0.0);
  for (int i = 0; i < count; i++)
    acc += texelFetch(src, clamp(p + ivec2(i % 8 - 4, (i / 8) % 8 - 4), ivec2(0), size - 1), 0);
  sum = acc / float(max(count, 1));
}
