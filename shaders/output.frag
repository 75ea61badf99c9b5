// The engine's output stage as a pass of its own (output.glsl says what it
// does), where it cannot run in the pass that wrote the presented image.
// OUTPUT_SIZED: the image has the output's size, read texel by texel.
#define OUTPUT_STAGE
#include "common.glsl"
#include "output.glsl"

in vec2 uv;
uniform sampler2D src;

void main() {
#ifdef OUTPUT_SIZED
  output_write(texelFetch(src, ivec2(gl_FragCoord.xy), 0).rgb); // the engine saw src is the output's size
#else
  output_write(texture(src, uv).rgb);
#endif
}
