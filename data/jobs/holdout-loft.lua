-- A held-out interior (data/gen_scenes.c's holdout_loft): a loft lit by the
-- sun through a skylight and an open door, its ceiling and an alcove lit by
-- bounce light only. Written after the GI defaults were chosen and never
-- tuned against: it says how the reference set's figures hold on a scene the
-- project has not seen (docs/gi-combined.md). A small size keeps Cycles'
-- references to about a minute a view on 2 cores:
--   build/limn reference --job data/jobs/holdout-loft.lua [--renderer cycles --samples 512]
--   build/limn report --job data/jobs/holdout-loft.lua --baseline dl+esm --sweep isr+esm ... (the same flags)
return {
  scenes = { "data/scenes/holdout/loft.glb" },
  techniques = { "dl+esm" },
  sizes = { "96x72" },
  set = { ambient = 0 },
  output = "out/holdout/{scene}/{camera}_{technique}.png",
}
