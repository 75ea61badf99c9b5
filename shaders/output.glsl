// The engine's output stage as a function: no NaN, Inf or negative value
// leaves it, in any mode; out_srgb is sRGB-encoded for 8-bit files and
// displays. Radiance arrives pre-exposed (common.glsl's exposed()) and
// leaves as radiance, in the float linear output whatever half floats would
// have held; DISPLAY values (present(t, "display"): tone mapped) leave as
// they are. output.frag runs it as a pass of its own; a pass recorded with
// fold_output runs it in place of writing its image (OUTPUT_STAGE, set by
// the engine: engine/render/render.c's add_output_stage).
#ifdef OUTPUT_STAGE
layout(location = 0) out vec4 out_srgb;
#ifdef LINEAR_OUTPUT
layout(location = 1) out vec4 out_linear;
#endif

void output_write(vec3 c) {
  c = finite_or_zero(c);
#ifndef DISPLAY
  c = min(c * frame.exposure.y, vec3(3e38));
#endif
  out_srgb = vec4(srgb_encode(c), 1.0);
#ifdef LINEAR_OUTPUT
  out_linear = vec4(c, 1.0);
#endif
}
#endif
