// Tiles (the seed viewer's F12): the image as square tiles of `size` pixels,
// each the colour at its centre, separated by grout lines `grout` pixels wide.
#include "post.glsl"

in vec2 uv;
uniform sampler2D src;
uniform float size = 16.0;         // tile side in pixels, >= 1
uniform float grout = 1.0;         // grout width in pixels, >= 0
uniform vec3 grout_color = vec3(0.05);

out vec4 dst;

void main() {
  vec2 px = gl_FragCoord.xy, dim = vec2(textureSize(src, 0));
  float s = max(size, 1.0);
  vec2 tile = floor(px / s), inside = px - tile * s; // 0 .. s in the tile
  vec2 centre = (tile + 0.5) * s;
  vec3 c = hdr_clamp(texture(src, clamp(centre, vec2(0.5), dim - 0.5) / dim).rgb, HALF_MAX);
  // Half the grout on each side of a tile, so that a line is `grout` wide.
  float g = 0.5 * clamp(grout, 0.0, s);
  bool in_grout = any(lessThan(inside, vec2(g))) || any(greaterThanEqual(inside, vec2(s - g)));
  dst = vec4(in_grout ? hdr_clamp(grout_color, HALF_MAX) : c, 1.0);
}
