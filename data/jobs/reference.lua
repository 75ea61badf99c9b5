-- The reference set: scenes where indirect light is a large share of the
-- image, every view exportable to POV-Ray exactly (limn reference, no
-- --approximate): a room lit through a window, a street with a shaded side,
-- blocks under a low sun, the Cornell box with its inverse-square light.
-- tools/fidelity.sh measures the GI techniques on it:
--   build/limn reference --job data/jobs/reference.lua
--   build/limn report --job data/jobs/reference.lua --baseline dl+esm --sweep isr+esm ...
-- ambient = 0: POV-Ray's export has no ambient term.
return {
  scenes = { "data/scenes/reference/room.glb", "data/scenes/reference/street.glb",
             "data/scenes/reference/blocks.glb", "data/scenes/cornell.glb" },
  techniques = { "dl+esm" },
  sizes = { "160x120" },
  set = { ambient = 0 },
  output = "out/reference-set/{scene}/{camera}_{technique}.png",
}
