// The "transparent" material technique's vertices: the same as std's.
#include "std.vert"
