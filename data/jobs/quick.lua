-- The reference set (reference.lua) at 80x60: the error-against-time table
-- that `tools/dev.sh run` prints, its references rendered once and cached.
-- The scenes as reference.lua lists them (a job file stands alone): job
-- files read alike.
return {
  scenes = { "data/scenes/reference/room.glb", "data/scenes/reference/street.glb",
             "data/scenes/reference/blocks.glb", "data/scenes/cornell.glb" },
  techniques = { "dl+esm" },
  sizes = { "80x60" },
  set = { ambient = 0 },
  output = "out/quick/{scene}/{camera}_{technique}.png",
}
