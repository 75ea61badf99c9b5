// limn bench: a texture to fetch from (values that do not fold away).
in vec2 uv;
out vec4 value;

void main() { value = vec4(uv, 1.0 - uv.x, 0.5); }
