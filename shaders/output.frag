// The engine's output stage as a pass of its own (output.glsl says what it
// does), where it cannot run in the pass that wrote the presented image.
#define OUTPUT_STAGE
#include "common.glsl"
#include "output.glsl"

in vec2 uv;
uniform sampler2D src;

void main() { output_write(texture(src, uv).rgb); }
