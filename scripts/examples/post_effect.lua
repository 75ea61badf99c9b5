-- Tutorial 1: a pipeline with a post effect of its own. The frame is the
-- G-buffer and its direct light (as pp.lua's `dl`), then tint.lua (next to
-- this script; its shader is shaders/examples/tint.frag) over the image.
--   limn capture --script scripts/examples/post_effect.lua --set tint.b=0.3 --output warm.png
local gbuffer = require "gbuffer"
local options = require "options"
local tint = require "tint"

Techniques = { "dl" }
Options = { ambient = 0.02, tint = options.copy(tint.defaults) }

function OnRender(tech)
  local G = gbuffer.render(gbuffer.targets())
  local a = tech.ambient
  local lit = pass{ "direct", shader = "direct.frag", inputs = gbuffer.inputs(G),
                    params = { ambient = { a, a, a } }, out = target{ "lit", format = "rgba16f" } }
  present(tint.render(lit, tech.tint, { G = G }))
end
