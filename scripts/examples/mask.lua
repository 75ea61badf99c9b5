-- A mask of the metallic surfaces: 1 where the pbr technique's G-buffer
-- holds metallic at least `metallic`, else 0 (shaders/examples/mask.frag).
-- `limn compare --mask` reads it to measure error over those pixels only
-- (tools/glossy_mask.sh: glossy indirect light on metals against Cycles).
--   limn capture --script scripts/examples/mask.lua --scene S --camera N --output mask.exr
local gbuffer = require "gbuffer"
local options = require "options"

Techniques = { "mask" }
Options = { metallic = 0.5 }

local rules = { metallic = options.number(0, 1) }

function OnRender(tech)
  options.fields(tech, rules, { "metallic" })
  local G = gbuffer.render(gbuffer.targets(1, "pbr"), "pbr")
  present(pass{ "mask", shader = "examples/mask.frag", inputs = gbuffer.inputs(G),
                params = { metallic = tech.metallic }, out = target{ "mask", format = "rgba8" } },
          "display") -- not light: no exposure
end
