-- A held-out exterior (data/gen_scenes.c's holdout_yard): a courtyard under
-- sky.lua's default sky and a low sun behind its back building, with a
-- mirror-like steel sphere, a brushed steel bench and a copper door. Written
-- after the GI defaults were chosen and never tuned against
-- (docs/gi-combined.md). The references take the same sky (`references.sky`,
-- sky.lua's defaults as export-pov's ZENITH:HORIZON[:INTENSITY]); POV-Ray draws
-- the metals as its closest finish (approximate), Cycles as glTF defines them
-- with --materials pbr:
--   build/limn reference --job data/jobs/holdout-yard.lua
--   build/limn report --job data/jobs/holdout-yard.lua --baseline dl+esm --sweep isr+esm ...
-- and with --renderer cycles --samples 512 --materials pbr against Cycles. POV-Ray gathers
-- the sky only through radiosity, so its direct-only floor (--radiosity off)
-- lacks the sky's light: against POV-Ray the report's gain over dl+esm is the
-- figure, against Cycles (whose floor keeps the sky's direct light) the share
-- of indirect error removed too. tools/glossy_mask.sh measures the metals.
return {
  scenes = { "data/scenes/holdout/yard.glb" },
  techniques = { "dl+esm" },
  sizes = { "96x72" },
  set = { ambient = 0, ["sky.enabled"] = true },
  references = { sky = "0.1,0.15,0.3:0.3,0.32,0.35:1", approximate = true },
  output = "out/holdout/{scene}/{camera}_{technique}.png",
}
