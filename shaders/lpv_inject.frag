// The injection's point values (lpv_inject.vert): a VPL's lobe per colour
// channel, or with GEOMETRY a surfel's blocking lobe, added into the volumes.
flat in vec4 v_r, v_g, v_b;
#ifdef GEOMETRY
out vec4 out_geometry;
#else
layout(location = 0) out vec4 out_r;
layout(location = 1) out vec4 out_g;
layout(location = 2) out vec4 out_b;
#endif

void main() {
#ifdef GEOMETRY
  out_geometry = v_r;
#else
  out_r = v_r;
  out_g = v_g;
  out_b = v_b;
#endif
}
