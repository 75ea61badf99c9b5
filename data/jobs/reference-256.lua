-- The reference set (data/jobs/reference.lua: the same scenes and views) at
-- 256 x 192, the size the frame-time targets are measured at
-- (tools/gi_time.sh): where a coarse grid's choice depends on the output's
-- size, judge it here. POV-Ray renders its 15 references once (about 2
-- minutes on 2 cores), cached under out/reference like the 160 x 120 ones:
--   build/limn report --job data/jobs/reference-256.lua --baseline dl+esm --sweep isr+rsm+esm ...
-- The scenes as reference.lua lists them (a job file stands alone): job
-- files read alike.
return {
  scenes = { "data/scenes/reference/room.glb", "data/scenes/reference/street.glb",
             "data/scenes/reference/blocks.glb", "data/scenes/cornell.glb" },
  techniques = { "dl+esm" },
  sizes = { "256x192" },
  set = { ambient = 0 },
  output = "out/reference-set-256/{scene}/{camera}_{technique}.png",
}
