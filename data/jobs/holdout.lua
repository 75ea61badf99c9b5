-- Held-out scenes (data/gen_scenes.c's holdout_loft and holdout_yard): an
-- interior lit through a skylight and a door, an exterior courtyard, both
-- under sky.lua's default sky. Written after the GI defaults were chosen and
-- never tuned against: they say how the reference set's figures hold on
-- scenes the project has not seen (docs/gi-combined.md). A small size keeps
-- Cycles' references to about a minute a view on 2 cores. The references
-- take the same sky (`--sky` is export-pov's ZENITH:HORIZON[:INTENSITY]):
--   build/limn reference --job data/jobs/holdout.lua --sky 0.1,0.15,0.3:0.3,0.32,0.35:1 --approximate
--   build/limn report --job data/jobs/holdout.lua --baseline dl+esm --sweep isr+esm ... (the same flags)
-- and with --renderer cycles --samples 512 against Cycles. --approximate: the
-- yard's metals have no exact POV-Ray finish (Phong frames draw them as
-- Phong's mapping of metallic-roughness; the Cycles references as glTF's).
return {
  scenes = { "data/scenes/holdout/loft.glb", "data/scenes/holdout/yard.glb" },
  techniques = { "dl+esm" },
  sizes = { "96x72" },
  set = { ambient = 0, ["sky.enabled"] = true },
  output = "out/holdout/{scene}/{camera}_{technique}.png",
}
